#!/usr/bin/env bash
# GUI smoke test: starts the real staged MeshLab GUI on a private Xvfb with a mesh
# carrying per-vertex colours, screenshots the screen and checks that the vertex
# colours are what MeshLab shows.
#
#   gui_screenshot.sh STAGE_BIN_DIR INPUT_PLY OUT_PNG
#
#   STAGE_BIN_DIR  folder holding the staged `meshlab` (build-ml/stage/bin)
#   INPUT_PLY      a PLY with per-vertex colours, or '-' to generate the test quad
#                  (make_colored_quad.py: left half red (230,40,40), right half
#                  green (40,200,60)) into a temporary folder, or '-grey' to
#                  generate the all-grey negative-control quad instead
#   OUT_PNG        where the screenshot is kept for people to look at (also on failure)
#
# Check: a screenshot pixel counts as "red" when r > 2g, r > 2b and r >= 60, and as
# "green" when g > 1.5r, g > 1.5b and g >= 60 (hue dominance, so MeshLab's lighting
# may darken or brighten the colours).  Both must cover at least GUI_MIN_FRACTION
# (default 0.02 = 2%) of the 1280x1024 screen, and the red area must lie left of
# the green one (the quad's left half is red).  MeshLab's own widgets hold no red or
# green area anywhere near 2% of the screen (only a few small icons).
#
# Negative control: a uniformly grey quad (INPUT_PLY '-grey', i.e.
# make_colored_quad.py --grey) is drawn by MeshLab as the same quad, lit grey; red
# then covers 0.1% of the screen (only the thin trackball axis line) and green 0.0%,
# so the script exits 1 with "too little red and green".  Hence a MeshLab that
# ignored the vertex colours (default grey), showed no mesh, or was covered by a
# dialog fails this test.  gui.cmake runs this control as its own CTest test.
#
# Exit status: 0 pass, 1 fail (one line "gui_screenshot: FAIL: <reason>" on stderr),
# 77 skipped (a required tool such as Xvfb, xdotool, ImageMagick or numpy missing).
# Runs as root or not, without a display or window manager; everything it starts
# (Xvfb, meshlab, a watchdog) is killed on exit, and a watchdog ends the whole run
# after GUI_TIMEOUT seconds (default 140, below CTest's 180; a normal run takes
# about 5 s, a failing one about 35 s).
#
# Environment knobs: GUI_NO_CHECK=1 (just take the screenshot), GUI_TIMEOUT, GUI_MIN_FRACTION, GUI_RENDER_WAIT (seconds to keep
# re-taking screenshots until the check passes, default 30), PYTHON, GUI_SCREEN_HEIGHT (default 1024);
# GUI_APPLY_AO=1 or GUI_APPLY_FILTER=name with GUI_APPLY_DOWNS=its place in its submenu of Filters
# (GUI_APPLY_MENU_DOWNS=the submenu's place, default 7: Color Creation and Processing; GUI_MENU_PEEK=1:
# screenshot that submenu and stop) and GUI_APPLY_LOG=text its log line must hold; GUI_SHOW_RASTER=1: then
# show the raster layer the filter made and run the colour check on it. GUI_EXPORT_PLY=path: after the filter,
# File -> Export Mesh As (Ctrl+Shift+E) to that path with MeshLab's default attributes, then compare it with
# GUI_EXPECT_PLY (what the command-line tool wrote for the same filter, mesh and parameters: vertex and face
# quality and colour must agree to GUI_EXPECT_TOL, default 0 = bit-identical). GUI_MESHLAB=2025.07 for a
# self-built MeshLab 2025.07 (see below).
#
# MeshLab 2020.09 quirks handled here:
#  * it keeps state in ~/.config/VCG/MeshLab_64bit_fp.conf (a loaded-mesh counter,
#    recent files, background colours, ...); after a network reply it may pop up a
#    "MeshLab Congratulations!" (more than 100 meshes opened) or "old version" dialog.
#    We run it with a throwaway HOME/XDG_CONFIG_HOME so every run is a first run
#    and no user setting leaks in.
#  * any other top-level window (e.g. "Meshlab Opening Error" for a missing file,
#    "Opening Failure" for a broken PLY) is reported and dismissed with Escape
#    (then Return) before the screenshot; none appears on a normal start.
#  * with no window manager the main window comes up at 0,0 with Qt's default size
#    (about 853x724); we resize it to fill the screen so the mesh is large.
#  * Qt warns when XDG_RUNTIME_DIR is unset; we give it a private one.  Xvfb has no
#    DRI, so Mesa renders with llvmpipe (LIBGL_ALWAYS_SOFTWARE=1 makes that explicit).
# MeshLab 2025.07 (upstream sources, without Debian's patch that turns these off)
# asks on its first start whether to send usage statistics (a modal question) and
# checks meshlab.net for a newer version: its throwaway configuration says the
# question was answered and not to remind about upgrades. It logs "Applied filter:
# NAME in N msec" where 2020.09 logs "Applied filter NAME". Its menus, dialogs and
# buttons are laid out as 2020.09's, so the same keyboard walk and clicks apply.
set -uo pipefail

me=gui_screenshot
fail() { printf '%s: FAIL: %s\n' "$me" "$*" >&2; exit 1; }
skip() { printf '%s: SKIP: %s\n' "$me" "$*" >&2; exit 77; }
note() { printf '%s: %s\n' "$me" "$*" >&2; }

(($# == 3)) || fail "usage: $0 STAGE_BIN_DIR INPUT_PLY|- OUT_PNG"
stage_bin=$1 input_ply=$2 out_png=$3
here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
timeout_s=${GUI_TIMEOUT:-140}
min_fraction=${GUI_MIN_FRACTION:-0.02}
render_wait=${GUI_RENDER_WAIT:-30}
width=1280 height=${GUI_SCREEN_HEIGHT:-1024}
t0=$SECONDS

for tool in Xvfb xdotool import convert xdpyinfo timeout; do
  command -v "$tool" >/dev/null 2>&1 || skip "required tool '$tool' not found (packages: xvfb xdotool imagemagick x11-utils coreutils)"
done
[[ -x "$stage_bin/meshlab" ]] || fail "no executable meshlab in '$stage_bin'"
stage_bin=$(cd "$stage_bin" && pwd)

# A python3 that has numpy (a venv's python3 on PATH may lack it).
py=
for cand in ${PYTHON:-} python3 /usr/bin/python3; do
  if "$cand" -c 'import numpy' >/dev/null 2>&1; then py=$cand; break; fi
done
[[ -n "$py" ]] || skip "no python3 with numpy found (set PYTHON)"

tmp=$(mktemp -d "${TMPDIR:-/tmp}/gui_screenshot.XXXXXX") || fail "mktemp failed"
xvfb_pid='' ml_pid='' dog_pid=''
stop() {  # stop PID: TERM, up to 3 s grace, then KILL
  local pid=$1
  [[ -n "$pid" ]] && kill -0 "$pid" 2>/dev/null || return 0
  kill -TERM "$pid" 2>/dev/null
  for _ in 1 2 3 4 5 6; do kill -0 "$pid" 2>/dev/null || break; sleep 0.5; done
  kill -KILL "$pid" 2>/dev/null
  wait "$pid" 2>/dev/null
}
cleanup() {
  stop "$ml_pid"
  stop "$xvfb_pid"
  [[ -n "$dog_pid" ]] && kill -TERM "$dog_pid" 2>/dev/null && wait "$dog_pid" 2>/dev/null
  rm -rf "$tmp"
}
trap cleanup EXIT
trap 'note "interrupted"; exit 1' INT HUP
trap 'fail "timed out after ${timeout_s}s (watchdog)"' TERM
# Watchdog: every blocking step below is itself bounded; this is the backstop.
(
  trap 'kill "$sp" 2>/dev/null; exit 0' TERM
  sleep "$timeout_s" & sp=$!
  wait "$sp" && kill -TERM $$
) >/dev/null 2>&1 &
dog_pid=$!

ml_log() { [[ -f "$tmp/meshlab.log" ]] && sed 's/^/  meshlab: /' "$tmp/meshlab.log" | tail -n 15 >&2; }

# ---- input mesh ----------------------------------------------------------------
if [[ "$input_ply" == - || "$input_ply" == -grey ]]; then
  if [[ "$input_ply" == -grey ]]; then input_ply=$tmp/grey_quad.ply; opt=--grey
  else input_ply=$tmp/colored_quad.ply; opt=; fi
  "$py" "$here/make_colored_quad.py" "$input_ply" $opt || fail "make_colored_quad.py failed"
fi
[[ -r "$input_ply" ]] || fail "cannot read input mesh '$input_ply'"
input_ply=$(cd "$(dirname "$input_ply")" && pwd)/$(basename "$input_ply")
mkdir -p "$(dirname "$out_png")" || fail "cannot create folder for '$out_png'"
rm -f "$out_png"

# ---- private X server: first free display from :90 up ----------------------------
disp=
for n in $(seq 90 189); do
  [[ -e /tmp/.X$n-lock || -e /tmp/.X11-unix/X$n ]] && continue
  Xvfb ":$n" -screen 0 "${width}x${height}x24" -nolisten tcp -noreset >"$tmp/xvfb.log" 2>&1 &
  xvfb_pid=$!
  for _ in $(seq 1 50); do  # up to 10 s for the server to answer
    # ours only if the lock file names our Xvfb (another run may have won :$n)
    if [[ "$(tr -dc 0-9 2>/dev/null <"/tmp/.X$n-lock")" == "$xvfb_pid" ]] \
       && timeout 5 xdpyinfo -display ":$n" >/dev/null 2>&1; then disp=:$n; break; fi
    kill -0 "$xvfb_pid" 2>/dev/null || break  # lost a race for this display: next one
    sleep 0.2
  done
  [[ -n "$disp" ]] && break
  stop "$xvfb_pid"; xvfb_pid=
done
[[ -n "$disp" ]] || { sed 's/^/  Xvfb: /' "$tmp/xvfb.log" | tail -n 5 >&2; fail "could not start Xvfb on any display :90-:189"; }
note "Xvfb on $disp"

# ---- MeshLab ---------------------------------------------------------------------
mkdir -p "$tmp/home/.config" "$tmp/home/.cache" "$tmp/runtime" && chmod 700 "$tmp/runtime"
applied="Applied filter"
if [[ "${GUI_MESHLAB:-2020.09}" == 2025.07 ]]; then
  mkdir -p "$tmp/home/.config/VCG"
  printf '[General]\ninformativeShown=true\ndontRemindMeAboutUpgrade=true\ndontRemindMeToSendEmail=true\n' \
    >"$tmp/home/.config/VCG/MeshLab_64bit_fp.conf"
  applied="Applied filter:"
fi
(
  unset WAYLAND_DISPLAY QT_QPA_PLATFORM
  export DISPLAY=$disp HOME=$tmp/home XDG_CONFIG_HOME=$tmp/home/.config \
    XDG_CACHE_HOME=$tmp/home/.cache XDG_RUNTIME_DIR=$tmp/runtime \
    LIBGL_ALWAYS_SOFTWARE=1 QT_X11_NO_MITSHM=1 QT_QPA_PLATFORM=xcb
  cd "$tmp" && exec "$stage_bin/meshlab" "$input_ply"
) >"$tmp/meshlab.log" 2>&1 &
ml_pid=$!

export DISPLAY=$disp
xdo() { timeout 10 xdotool "$@" 2>/dev/null; }
main_re='^MeshLab.*\['   # "MeshLab 2020.09 - [Project_1]"; not "MeshLab Congratulations!"
main_win=
dismissed=()
dismiss_dialogs() {  # Escape (then Return) every other visible named top-level window
  local w name round
  for round in 1 2 3; do
    local others=()
    for w in $(xdo search --onlyvisible --maxdepth 1 --name .); do
      [[ "$w" == "$main_win" ]] && continue
      name=$(xdo getwindowname "$w") || continue
      [[ "$name" =~ $main_re ]] && continue
      others+=("$w")
      [[ " ${dismissed[*]-} " == *" $w "* ]] || { dismissed+=("$w"); note "dismissing dialog window '$name'"; }
      xdo windowfocus "$w"
      if ((round < 3)); then xdo key --clearmodifiers Escape; else xdo key --clearmodifiers Return; fi
    done
    ((${#others[@]})) || return 0
    sleep 1
  done
}

deadline=$((SECONDS + 60))
while :; do
  kill -0 "$ml_pid" 2>/dev/null || { ml_log; fail "meshlab exited before showing its main window"; }
  main_win=$(xdo search --onlyvisible --maxdepth 1 --name "$main_re" | head -n 1)
  [[ -n "$main_win" ]] && break
  ((SECONDS < deadline)) || { ml_log; fail "no MeshLab main window after 60 s"; }
  # a modal dialog shown before the main window would block it: dismiss it
  [[ -n "$(xdo search --onlyvisible --maxdepth 1 --name .)" ]] && dismiss_dialogs
  sleep 0.5
done
note "main window '$(xdo getwindowname "$main_win")' after $((SECONDS - t0)) s"
# MeshLab logs "All files opened" once the mesh is loaded (soft wait, at most 20 s).
for _ in $(seq 1 40); do
  grep -q "All files opened" "$tmp/meshlab.log" 2>/dev/null && break
  sleep 0.5
done
# No window manager: place and size the window ourselves.  MeshLab may still
# resize itself right after start-up (seen once in ~10 runs), so this is checked
# again before every screenshot.
fill_screen() {
  # shellcheck disable=SC2034  # all set by --shell's output; SCREEN, WINDOW unused
  local WIDTH='' HEIGHT='' X='' Y='' SCREEN='' WINDOW=''
  eval "$(xdo getwindowgeometry --shell "$main_win")"
  [[ "$WIDTH" == "$width" && "$HEIGHT" == "$height" && "$X" == 0 && "$Y" == 0 ]] && return 0
  xdo windowmove "$main_win" 0 0
  xdo windowsize "$main_win" "$width" "$height"
  sleep 2
}
# A new visible top-level window whose name matches $1, within $2 seconds.
wait_window() {
  local w deadline=$((SECONDS + $2))
  while ((SECONDS < deadline)); do
    w=$(xdo search --onlyvisible --maxdepth 1 --name "$1" | head -n 1)
    [[ -n "$w" ]] && { echo "$w"; return 0; }
    sleep 0.5
  done
  return 1
}
# GUI_EXPORT_PLY: close the filter's dialog, File -> Export Mesh As (Ctrl+Shift+E),
# type the path into the file dialog, accept MeshLab's default attributes (vertex
# and face colour and quality are ticked when the mesh has them), then compare
# what MeshLab wrote with GUI_EXPECT_PLY.
export_and_compare() {
  local dlg
  xdo mousemove $((X + WIDTH / 4)) $((Y + HEIGHT - 15)) click 1; sleep 1  # Close
  rm -f "$GUI_EXPORT_PLY"
  xdo windowfocus "$main_win"; sleep 0.5
  xdo key --clearmodifiers ctrl+shift+e
  dlg=$(wait_window '^Save .*Layer' 15) || { timeout 30 import -window root "$out_png"; fail "no file dialog after Ctrl+Shift+E (screenshot: $out_png)"; }
  xdo windowfocus "$dlg"; sleep 0.5
  xdo key --clearmodifiers ctrl+a; xdo type --delay 5 "$GUI_EXPORT_PLY"; xdo key Return
  dlg=$(wait_window '^Choose Saving Options' 15) || { timeout 30 import -window root "$out_png"; fail "no saving options after the file dialog (screenshot: $out_png)"; }
  xdo windowfocus "$dlg"; sleep 0.5
  xdo key Return  # OK
  for _ in $(seq 1 60); do
    grep -qF "Saved Mesh $GUI_EXPORT_PLY" "$tmp/meshlab.log" 2>/dev/null && break
    sleep 0.5
  done
  [[ -s "$GUI_EXPORT_PLY" ]] || { ml_log; fail "MeshLab did not write $GUI_EXPORT_PLY"; }
  [[ -n "${GUI_EXPECT_PLY:-}" ]] || return 0
  verdict=$(timeout 60 "$py" "$here/gui_compare_ply.py" "$GUI_EXPORT_PLY" "$GUI_EXPECT_PLY" "${GUI_EXPECT_TOL:-0}" 2>&1) \
    || fail "the mesh MeshLab wrote differs from the command-line tool's: ${verdict##*$'\n'}"
  note "written mesh: ${verdict##*$'\n'}"
}
fill_screen
sleep 2  # llvmpipe is slow to draw the first frames

# ---- screenshot + check (retaken until it passes or GUI_RENDER_WAIT runs out) -----
check_py=$(cat <<'PY'
import re, sys, numpy as np
ppm, min_frac = sys.argv[1], float(sys.argv[2])
data = open(ppm, "rb").read()
# binary PPM from convert: "P6 W H 255" + one whitespace, then RGB bytes
m = re.match(rb"P6\s+(\d+)\s+(\d+)\s+255\s", data)
w, h = (int(m.group(1)), int(m.group(2))) if m else (0, 0)
if not m or len(data) < m.end() + w * h * 3 or w * h == 0:
    print("the screenshot did not convert to an 8-bit binary PPM"); sys.exit(1)
img = np.frombuffer(data, np.uint8, w * h * 3, m.end()).reshape(h, w, 3).astype(np.int32)
r, g, b = img[..., 0], img[..., 1], img[..., 2]
red = (r > 2 * g) & (r > 2 * b) & (r >= 60)
green = (2 * g > 3 * r) & (2 * g > 3 * b) & (g >= 60)
fr, fg = red.mean(), green.mean()
msg = f"red {100*fr:.1f}%, green {100*fg:.1f}% of the {w}x{h} screen (need >= {100*min_frac:.1f}% each)"
if fr < min_frac or fg < min_frac:
    missing = " and ".join(n for n, f in (("red", fr), ("green", fg)) if f < min_frac)
    print(f"too little {missing} in the screenshot: {msg}"); sys.exit(1)
xr, xg = np.nonzero(red)[1].mean(), np.nonzero(green)[1].mean()
if not xr < xg:
    print(f"red area (mean x {xr:.0f}) is not left of green area (mean x {xg:.0f}): {msg}"); sys.exit(1)
print(f"{msg}; red left of green (mean x {xr:.0f} < {xg:.0f})")
PY
)
apply_name=${GUI_APPLY_FILTER:-} apply_downs=${GUI_APPLY_DOWNS:-15}
[[ "${GUI_APPLY_AO:-0}" == 1 ]] && apply_name="GI: Ambient Occlusion" apply_downs=15
if [[ -n "$apply_name" ]]; then
  # Apply a filter the way a person does: Filters menu -> Color Creation and
  # Processing -> the filter (the apply_downs-th entry) -> Apply. The keyboard
  # walk relies on Debian's MeshLab 2020.09 menus (fixed order).
  sleep 2
  xdo mousemove 120 11 click 1; sleep 1
  for _ in $(seq 1 "${GUI_APPLY_MENU_DOWNS:-7}"); do xdo key Down; done; sleep 0.3
  xdo key Right; sleep 1
  if [[ "${GUI_MENU_PEEK:-0}" == 1 ]]; then timeout 30 import -window root "$out_png"; note "menu screenshot $out_png"; exit 0; fi
  for _ in $(seq 1 "$apply_downs"); do xdo key Down; done; sleep 0.3
  xdo key Return; sleep 2
  dlg=$(xdo search --onlyvisible --name "^$apply_name\$" | head -n 1)
  [[ -n "$dlg" ]] || { timeout 30 import -window root "$out_png"; fail "the $apply_name dialog did not open (screenshot: $out_png)"; }
  # shellcheck disable=SC2034
  WIDTH='' HEIGHT='' X='' Y='' SCREEN='' WINDOW=''
  eval "$(xdo getwindowgeometry --shell "$dlg")"
  xdo mousemove $((X + WIDTH * 3 / 4)) $((Y + HEIGHT - 15)) click 1  # the Apply button
  for _ in $(seq 1 120); do
    grep -qF "$applied $apply_name" "$tmp/meshlab.log" 2>/dev/null && break
    sleep 0.5
  done
  sleep 2
  timeout 30 import -window root "$out_png" || fail "import -window root failed"
  grep -qF "$applied $apply_name" "$tmp/meshlab.log" || { ml_log; fail "MeshLab did not report $apply_name applied (screenshot: $out_png)"; }
  grep -q "${GUI_APPLY_LOG:-$apply_name: vertices=}" "$tmp/meshlab.log" || { ml_log; fail "no log line of $apply_name (screenshot: $out_png)"; }
  if [[ -n "${GUI_EXPORT_PLY:-}" ]]; then export_and_compare; fi
  if [[ "${GUI_SHOW_RASTER:-0}" != 1 ]]; then
    note "PASS: $apply_name applied from the GUI menus; screenshot $out_png; $((SECONDS - t0)) s"
    exit 0
  fi
  # The filter made a raster layer: close the dialog and show it (View ->
  # Show Current Raster Mode, Shift+R); the colour check below must then
  # find the rendered Cornell box's red wall left of its green one.
  xdo mousemove $((X + WIDTH / 4)) $((Y + HEIGHT - 15)) click 1; sleep 1  # Close
  # A main window of the usual shape (the tall screen was for the dialog) shows the whole picture.
  height=1024
  fill_screen
  # GUI_RASTER_CONTROL=1: the negative control, the same without showing the raster.
  [[ "${GUI_RASTER_CONTROL:-0}" == 1 ]] || { xdo windowfocus "$main_win"; xdo mousemove 600 400; xdo key --clearmodifiers shift+r; }
  sleep 2
  note "$apply_name applied from the GUI menus; showing its raster layer"
fi
if [[ "${GUI_NO_CHECK:-0}" == 1 ]]; then
  # Documentation screenshots (scripts/make_figures.sh): no colour check.
  sleep "${GUI_SETTLE:-4}"
  dismiss_dialogs
  fill_screen
  timeout 30 import -window root "$out_png" || fail "import -window root failed"
  note "screenshot $out_png (no check)"
  exit 0
fi
verdict='' status=1
shot_deadline=$((SECONDS + render_wait))
while :; do
  kill -0 "$ml_pid" 2>/dev/null || { ml_log; fail "meshlab exited before the screenshot"; }
  dismiss_dialogs
  fill_screen
  timeout 30 import -window root "$out_png" 2>"$tmp/import.log" \
    || { cat "$tmp/import.log" >&2; fail "import -window root failed"; }
  timeout 30 convert "$out_png" -depth 8 ppm:- >"$tmp/shot.ppm" 2>"$tmp/convert.log" \
    || { cat "$tmp/convert.log" >&2; fail "convert of the screenshot to PPM failed"; }
  verdict=$(timeout 30 "$py" -c "$check_py" "$tmp/shot.ppm" "$min_fraction" 2>&1); status=$?
  verdict=${verdict##*$'\n'}  # last line only (a traceback ends with the error)
  ((status == 0)) && break
  ((SECONDS + 3 < shot_deadline)) || break
  sleep 3
done
((status == 0)) || { ml_log; fail "$verdict (screenshot: $out_png)"; }
note "PASS: $verdict; screenshot $out_png; $((SECONDS - t0)) s"
exit 0

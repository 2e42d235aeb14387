# GUI tests in MeshLab 2025.07 (GI_MESHLAB_TARGET=2025.07; scripts/build_meshlab2025.sh --test):
# the staged self-built MeshLab 2025.07 (cmake/StageMeshLab2025.cmake) on a private
# Xvfb, driven by gui_screenshot.sh as the 2020.09 GUI tests drive Debian's MeshLab.
#   ctest -L gui2025 --output-on-failure
# Every filter of the catalogue is applied from the Filters menu with its dialog's
# defaults; MeshLab must report it applied and log our line; the mesh is then
# exported through File -> Export Mesh As and must equal, vertex for vertex, what
# the command-line tool writes for the same filter, mesh and parameters (same
# seed: vertex and face quality and colour identical, or within what the
# dialog's rounding of a distance explains, see below). The screenshots stay in
# the build folder (gui2025_*.png).
# MeshLab 2025.07 has no meshlabserver: its scripting is PyMeshLab, a separate
# Python package not built here, so the .mlx tests stay on 2020.09.
set(_gui "${CMAKE_CURRENT_LIST_DIR}/gui_screenshot.sh")
set(_meshes "${PROJECT_SOURCE_DIR}/test_meshes")
set(_out "${CMAKE_BINARY_DIR}/gui2025")
file(MAKE_DIRECTORY "${_out}")

# MeshLab 2025.07 shows a vertex-coloured mesh in its colours; a grey one fails the check.
add_test(NAME gui2025_screenshot COMMAND bash ${_gui} ${GI_STAGE_DIR}/bin - ${_out}/screenshot.png)
set_tests_properties(gui2025_screenshot PROPERTIES TIMEOUT 180 LABELS gui2025 SKIP_RETURN_CODE 77
  ENVIRONMENT "GUI_MESHLAB=2025.07")
add_test(NAME gui2025_screenshot_grey_control COMMAND bash ${_gui} ${GI_STAGE_DIR}/bin -grey ${_out}/screenshot_grey.png)
set_tests_properties(gui2025_screenshot_grey_control PROPERTIES TIMEOUT 180 LABELS gui2025
  SKIP_REGULAR_EXPRESSION "gui_screenshot: SKIP:"
  PASS_REGULAR_EXPRESSION "gui_screenshot: FAIL: too little red and green in the screenshot"
  ENVIRONMENT "GUI_MESHLAB=2025.07;GUI_RENDER_WAIT=6")

# The face the form-factor filter starts from, selected in the mesh MeshLab opens
# (the dialog's default Face -1 = the selected face); the CLI is given its index.
set(_ff_face 5)
add_test(NAME gui2025_select_face
  COMMAND ${GI_PYTHON3} ${CMAKE_CURRENT_LIST_DIR}/gui_select_face.py ${_meshes}/cornell_box.ply ${_ff_face}
          ${_out}/cornell_box_face${_ff_face}_selected.ply)
set_tests_properties(gui2025_select_face PROPERTIES LABELS gui2025 FIXTURES_SETUP gui2025_formfactors)

# What MeshLab 2025.07's dialog hands the filter is what its fields show: a float
# field shows three significant digits (QString::number(v, 'g', 3) in its
# common_gui float widget), so the default emitter radiosity 53.407 W/m^2 is
# applied as 53.4; the command-line run is given the same. A distance field (abs
# and %) keeps 7 - ceil(log10(range)) decimals of its range: 4 here, on both
# meshes (diagonals 15.76 x 10 and 960.74), i.e. |error| <= 5e-5. That moves
#   obscurance's d_max = 1.576 (bunny) by <= 3.2e-5 relative: each ray's term
#     min(1, d/d_max) and so the quality (<= 1, mean 0.9) by <= 3.2e-5: TOL 5e-5;
#   photon mapping's gather radius r = 48.04 (Cornell box) by <= 1.04e-6
#     relative: a density estimate ~ 1/r^2 by <= 2.1e-6: TOL 5e-6 (a photon
#     within 5e-5 of the radius would add a step: none is, the result being
#     deterministic this holds or fails for good).
# The other filters must write exactly what the CLI writes (TOL 0).
# Fields: name in the menu | CLI subcommand | mesh MeshLab opens | CLI arguments |
# place in Filters -> Color Creation and Processing (0 = first: only our filters are
# there, alphabetical) | screen height (a tall dialog keeps Apply on screen) | TOL.
set(_e53 "--emitter_intensity 53.4")
set(_cases
  "Ambient Obscurance|obscurance|bunny.ply|test_meshes/bunny.ply|0|1024|5e-5"
  "Ambient Occlusion|ao|bunny.ply|test_meshes/bunny.ply|1|1024|0"
  "Form Factors of Selected Face|formfactors|@ff|test_meshes/cornell_box.ply --face_index ${_ff_face}|3|1024|0"
  "Path Traced Reference|reference|cornell_box.ply|test_meshes/cornell_box.ply ${_e53}|4|2200|0"
  "Photon Mapping|photonmap|cornell_box.ply|test_meshes/cornell_box.ply ${_e53}|5|2200|5e-6"
  "Radiosity|radiosity|cornell_box.ply|test_meshes/cornell_box.ply ${_e53}|6|2000|0"
  "Sky Lighting|sky|bunny.ply|test_meshes/bunny.ply|7|1024|0")
foreach(c ${_cases})
  string(REPLACE "|" ";" c "${c}")
  list(GET c 0 name)
  list(GET c 1 sub)
  list(GET c 2 mesh)
  list(GET c 3 cli_args)
  list(GET c 4 downs)
  list(GET c 5 screen)
  list(GET c 6 tol)
  separate_arguments(cli_args UNIX_COMMAND "${cli_args}")
  list(TRANSFORM cli_args REPLACE "^test_meshes/" "${_meshes}/")
  if(mesh STREQUAL "@ff")
    set(mesh "${_out}/cornell_box_face${_ff_face}_selected.ply")
    set(fixtures "gui2025_expect_${sub};gui2025_formfactors")
  else()
    set(mesh "${_meshes}/${mesh}")
    set(fixtures "gui2025_expect_${sub}")
  endif()
  # What the command-line tool writes with the same defaults.
  add_test(NAME gui2025_expect_${sub} COMMAND $<TARGET_FILE:gi> ${sub} ${cli_args} -o ${_out}/${sub}_cli.ply)
  set_tests_properties(gui2025_expect_${sub} PROPERTIES LABELS gui2025 TIMEOUT 120 FIXTURES_SETUP gui2025_expect_${sub})
  add_test(NAME gui2025_apply_${sub} COMMAND bash ${_gui} ${GI_STAGE_DIR}/bin ${mesh} ${_out}/apply_${sub}.png)
  set_tests_properties(gui2025_apply_${sub} PROPERTIES TIMEOUT 180 LABELS gui2025 SKIP_RETURN_CODE 77
    FIXTURES_REQUIRED "${fixtures}"
    FIXTURES_SETUP gui2025_written_${sub}
    ENVIRONMENT "GUI_MESHLAB=2025.07;GUI_APPLY_FILTER=GI: ${name};GUI_APPLY_DOWNS=${downs};GUI_SCREEN_HEIGHT=${screen};GUI_APPLY_LOG=GI: ${name}: ;GUI_EXPORT_PLY=${_out}/${sub}_gui.ply;GUI_EXPECT_PLY=${_out}/${sub}_cli.ply;GUI_EXPECT_TOL=${tol}")
endforeach()

# Control: the comparison must see a change as small as the dialog's rounding of
# the emitter radiosity (53.407 -> 53.4, 1.3e-4 relative): the photon-mapped mesh
# MeshLab wrote against the CLI's at 53.407, with photon mapping's tolerance.
add_test(NAME gui2025_expect_photonmap_53.407
  COMMAND $<TARGET_FILE:gi> photonmap ${_meshes}/cornell_box.ply --emitter_intensity 53.407 -o ${_out}/photonmap_cli_53.407.ply)
set_tests_properties(gui2025_expect_photonmap_53.407 PROPERTIES LABELS gui2025 TIMEOUT 120
  FIXTURES_SETUP gui2025_expect_photonmap_53.407)
add_test(NAME gui2025_written_mesh_control
  COMMAND ${GI_PYTHON3} ${CMAKE_CURRENT_LIST_DIR}/gui_compare_ply.py ${_out}/photonmap_gui.ply
          ${_out}/photonmap_cli_53.407.ply 5e-6)
set_tests_properties(gui2025_written_mesh_control PROPERTIES LABELS gui2025
  FIXTURES_REQUIRED "gui2025_written_photonmap;gui2025_expect_photonmap_53.407"
  PASS_REGULAR_EXPRESSION "vertex values differ beyond the tolerance")

# GI: Ray Traced View from Filters -> Raster Layer (its 2nd entry here, after GI: Hemicube of Selected Face), then View ->
# Show Current Raster Mode: the picture must be the rendered Cornell box (red wall left
# of the green one). The control shows the plain mesh view and must fail the check.
set(_rt "GUI_MESHLAB=2025.07;GUI_APPLY_FILTER=GI: Ray Traced View;GUI_APPLY_MENU_DOWNS=12;GUI_APPLY_DOWNS=1;GUI_SCREEN_HEIGHT=2400;GUI_APPLY_LOG=GI: Ray Traced View: ;GUI_SHOW_RASTER=1")
add_test(NAME gui2025_apply_ray_traced_view
  COMMAND bash ${_gui} ${GI_STAGE_DIR}/bin ${_meshes}/cornell_box.ply ${_out}/apply_ray_traced_view.png)
set_tests_properties(gui2025_apply_ray_traced_view PROPERTIES TIMEOUT 180 LABELS gui2025 SKIP_RETURN_CODE 77
  ENVIRONMENT "${_rt}")
add_test(NAME gui2025_ray_traced_view_control
  COMMAND bash ${_gui} ${GI_STAGE_DIR}/bin ${_meshes}/cornell_box.ply ${_out}/ray_traced_view_control.png)
set_tests_properties(gui2025_ray_traced_view_control PROPERTIES TIMEOUT 180 LABELS gui2025
  SKIP_REGULAR_EXPRESSION "gui_screenshot: SKIP:"
  PASS_REGULAR_EXPRESSION "gui_screenshot: FAIL: too little red and green in the screenshot"
  ENVIRONMENT "${_rt};GUI_RASTER_CONTROL=1;GUI_RENDER_WAIT=6")

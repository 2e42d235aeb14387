# GUI tests: the real staged MeshLab GUI on a private Xvfb, checked by screenshot.
# include()d from tests/integration/CMakeLists.txt; needs GI_STAGE_DIR (set by
# cmake/StageMeshLab.cmake) and, at test time, xvfb, xdotool, imagemagick,
# x11-utils and python3-numpy (the script exits 77 = skipped if one is missing).
#   ctest -L gui --output-on-failure
# The screenshots stay in the build folder for people to look at.
if(NOT DEFINED GI_STAGE_DIR)
  message(STATUS "gui tests: GI_STAGE_DIR not set (no staged MeshLab), not added")
else()
  # '-' : the script generates make_colored_quad.py's red/green quad itself.
  add_test(NAME gui_screenshot
    COMMAND bash ${CMAKE_CURRENT_LIST_DIR}/gui_screenshot.sh
            ${GI_STAGE_DIR}/bin - ${CMAKE_BINARY_DIR}/gui_screenshot.png)
  set_tests_properties(gui_screenshot PROPERTIES
    TIMEOUT 180
    LABELS gui
    SKIP_RETURN_CODE 77
    ATTACHED_FILES_ON_FAIL ${CMAKE_BINARY_DIR}/gui_screenshot.png)

  # Negative control: the same quad in plain grey must make the colour check fail
  # (and only the colour check: MeshLab must have come up and been screenshotted).
  add_test(NAME gui_screenshot_grey_control
    COMMAND bash ${CMAKE_CURRENT_LIST_DIR}/gui_screenshot.sh
            ${GI_STAGE_DIR}/bin -grey ${CMAKE_BINARY_DIR}/gui_screenshot_grey.png)
  set_tests_properties(gui_screenshot_grey_control PROPERTIES
    TIMEOUT 180
    LABELS gui
    SKIP_REGULAR_EXPRESSION "gui_screenshot: SKIP:"
    PASS_REGULAR_EXPRESSION "gui_screenshot: FAIL: too little red and green in the screenshot"
    # the check retakes screenshots until it passes; for the control a few s will do
    ENVIRONMENT "GUI_RENDER_WAIT=6")

  # A person's use of our filter: open a mesh, Filters -> Color Creation and
  # Processing -> GI: Ambient Occlusion -> Apply; MeshLab must log our line.
  add_test(NAME gui_apply_ambient_occlusion
    COMMAND bash ${CMAKE_CURRENT_LIST_DIR}/gui_screenshot.sh
            ${GI_STAGE_DIR}/bin ${PROJECT_SOURCE_DIR}/test_meshes/bunny.ply ${CMAKE_BINARY_DIR}/gui_apply_ao.png)
  set_tests_properties(gui_apply_ambient_occlusion PROPERTIES
    TIMEOUT 180
    LABELS gui
    SKIP_RETURN_CODE 77
    ENVIRONMENT "GUI_APPLY_AO=1")

  # The same for GI: Radiosity and GI: Photon Mapping on the Cornell box (its
  # light marked by face quality: the default 'Auto' emitters find it). Their
  # dialogs are taller than 1024 pixels: a taller screen keeps Apply visible.
  # The numbers are the filters' places in the alphabetical submenu.
  foreach(f "Radiosity;20;2000;radiosity" "Photon Mapping;19;2200;photon_mapping")
    list(GET f 0 name)
    list(GET f 1 downs)
    list(GET f 2 screen)
    list(GET f 3 id)
    add_test(NAME gui_apply_${id}
      COMMAND bash ${CMAKE_CURRENT_LIST_DIR}/gui_screenshot.sh
              ${GI_STAGE_DIR}/bin ${PROJECT_SOURCE_DIR}/test_meshes/cornell_box.ply ${CMAKE_BINARY_DIR}/gui_apply_${id}.png)
    set_tests_properties(gui_apply_${id} PROPERTIES
      TIMEOUT 180
      LABELS gui
      SKIP_RETURN_CODE 77
      ENVIRONMENT "GUI_APPLY_FILTER=GI: ${name};GUI_APPLY_DOWNS=${downs};GUI_SCREEN_HEIGHT=${screen};GUI_APPLY_LOG=GI: ${name}: ")
  endforeach()

  # GI: Ray Traced View from Filters -> Raster Layer (its 5th entry, after GI: Hemicube of Selected Face), then
  # View -> Show Current Raster Mode: the picture on screen must be the
  # rendered Cornell box (red wall left of the green one, seen through the
  # raster's camera). The control shows the plain mesh view instead (the box
  # seen from behind, no red or green) and must fail the colour check.
  set(_rt "GUI_APPLY_FILTER=GI: Ray Traced View;GUI_APPLY_MENU_DOWNS=12;GUI_APPLY_DOWNS=4;GUI_SCREEN_HEIGHT=2400;GUI_APPLY_LOG=GI: Ray Traced View: ;GUI_SHOW_RASTER=1")
  add_test(NAME gui_apply_ray_traced_view
    COMMAND bash ${CMAKE_CURRENT_LIST_DIR}/gui_screenshot.sh
            ${GI_STAGE_DIR}/bin ${PROJECT_SOURCE_DIR}/test_meshes/cornell_box.ply ${CMAKE_BINARY_DIR}/gui_apply_ray_traced_view.png)
  set_tests_properties(gui_apply_ray_traced_view PROPERTIES TIMEOUT 180 LABELS gui SKIP_RETURN_CODE 77 ENVIRONMENT "${_rt}")
  add_test(NAME gui_ray_traced_view_control
    COMMAND bash ${CMAKE_CURRENT_LIST_DIR}/gui_screenshot.sh
            ${GI_STAGE_DIR}/bin ${PROJECT_SOURCE_DIR}/test_meshes/cornell_box.ply ${CMAKE_BINARY_DIR}/gui_ray_traced_view_control.png)
  set_tests_properties(gui_ray_traced_view_control PROPERTIES TIMEOUT 180 LABELS gui
    SKIP_REGULAR_EXPRESSION "gui_screenshot: SKIP:"
    PASS_REGULAR_EXPRESSION "gui_screenshot: FAIL: too little red and green in the screenshot"
    ENVIRONMENT "${_rt};GUI_RASTER_CONTROL=1;GUI_RENDER_WAIT=6")
endif()

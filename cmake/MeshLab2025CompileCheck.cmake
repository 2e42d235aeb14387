# In the default (2020.09) build: the bridge and the five plugins compiled (not
# linked) against MeshLab 2025.07's headers as well, so that a change that breaks
# the 2025.07 target fails every build, though CI does not build MeshLab 2025.07
# itself (scripts/build_meshlab2025.sh does). The plugins' moc output instantiates
# each plugin class: a hook 2025.07 declares pure and we miss fails here.
# Needs the sources that `scripts/setup_meshlab2025.sh --sources` unpacks
# (scripts/setup.sh runs it); without them the check is left out, with a message.
set(GI_MESHLAB2025_HOME "${PROJECT_SOURCE_DIR}/.deps/meshlab-2025.07" CACHE PATH
    "Where scripts/setup_meshlab2025.sh keeps MeshLab 2025.07's sources (meshlab/) and build (build/)")
set(_src2025 "${GI_MESHLAB2025_HOME}/meshlab/src")
if(NOT EXISTS "${_src2025}/common/plugins/interfaces/filter_plugin.h")
  message(STATUS "MeshLab 2025.07 compile check left out: no sources in ${_src2025} "
                 "(bash scripts/setup_meshlab2025.sh --sources)")
  return()
endif()
find_package(Qt5 REQUIRED COMPONENTS Network)
# One object library per plugin: each plugin's moc output defines Qt's plugin
# entry points, one set per shared object.
set(_units "bridge:bridge/ml_compat.cpp bridge/gi_plugin.cpp bridge/meshlab_bridge.cpp bridge/mesh_replace.cpp")
foreach(p ambient radiosity photonmap reference raytrace)
  list(APPEND _units "filter_${p}:filter_${p}/filter_${p}.cpp")
endforeach()
add_custom_target(gi_meshlab2025_compile_check ALL)
foreach(u ${_units})
  string(REGEX REPLACE ":.*" "" name "${u}")
  string(REGEX REPLACE "^[^:]*:" "" files "${u}")
  separate_arguments(files)
  set(t gi_ml2025_check_${name})
  add_library(${t} OBJECT ${files})
  set_target_properties(${t} PROPERTIES AUTOMOC ON)
  target_include_directories(${t} PRIVATE bridge)
  target_include_directories(${t} SYSTEM PRIVATE "${_src2025}" "${_src2025}/vcglib" ${EIGEN3_INCLUDE_DIR})
  target_compile_definitions(${t} PRIVATE MESHLAB_SCALAR=float MESHLAB_VERSION=2025.07 GI_MESHLAB_2025)
  # Usage requirements only (include folders, Qt's definitions): nothing is linked.
  target_link_libraries(${t} PRIVATE gi_core gi_io_ply gi_io_files Qt5::Core Qt5::Gui Qt5::Widgets Qt5::OpenGL Qt5::Xml Qt5::Network)
  target_compile_options(${t} PRIVATE ${GI_WARNINGS})
  add_dependencies(gi_meshlab2025_compile_check ${t})
endforeach()
message(STATUS "MeshLab 2025.07 compile check of the bridge and plugins: ${_src2025}")

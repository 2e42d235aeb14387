# Imported target meshlab::common for the MeshLab version the plugins are built
# for (GI_MESHLAB_TARGET):
#   2020.09 (default): the headers of Debian 12's MeshLab (src/common and vcglib
#     from Debian's source package, fetched by scripts/setup.sh) and the installed
#     libmeshlab-common.so; the plugins load in Debian's meshlab and meshlabserver.
#   2025.07: the headers and libmeshlab-common.so of a MeshLab 2025.07 build:
#     the one scripts/setup_meshlab2025.sh makes (GUI + PLY reader, cached), or
#     your own (GI_MESHLAB_SOURCE_DIR = MeshLab's src/ folder, GI_MESHLAB_DISTRIB_DIR =
#     its build's distrib/ folder). The plugins load in that MeshLab build.
# The bridge's differences between the two are in bridge/ml_compat.h only.
set(GI_MESHLAB_TARGET "2020.09" CACHE STRING "MeshLab version to build the plugins for: 2020.09 or 2025.07")
set_property(CACHE GI_MESHLAB_TARGET PROPERTY STRINGS "2020.09" "2025.07")

if(GI_MESHLAB_TARGET STREQUAL "2020.09")
  set(MESHLAB_SDK_DIR "${PROJECT_SOURCE_DIR}/.deps/meshlab-sdk" CACHE PATH "MeshLab 2020.09 SDK (src/common + vcglib)")
  set(MESHLAB_LIB_DIR "/usr/lib/${CMAKE_LIBRARY_ARCHITECTURE}/meshlab" CACHE PATH "Folder of libmeshlab-common.so and plugins/")
  if(NOT EXISTS "${MESHLAB_SDK_DIR}/src/common/interfaces.h")
    message(FATAL_ERROR "MeshLab SDK not found in ${MESHLAB_SDK_DIR}: run scripts/setup.sh first")
  endif()
  set(_ml_include "${MESHLAB_SDK_DIR}/src" "${MESHLAB_SDK_DIR}/vcglib")
  set(_ml_defs MESHLAB_SCALAR=float)
  set(_ml_qt Core Gui Widgets OpenGL Xml XmlPatterns)
  # Debian's MeshLab loads plugins from <prefix of its binary>/lib/<arch>/meshlab/plugins,
  # i.e. /usr/lib/<arch>/meshlab/plugins: install there whatever CMAKE_INSTALL_PREFIX is.
  set(_ml_plugins "${MESHLAB_LIB_DIR}/plugins")
elseif(GI_MESHLAB_TARGET STREQUAL "2025.07")
  set(GI_MESHLAB2025_HOME "${PROJECT_SOURCE_DIR}/.deps/meshlab-2025.07" CACHE PATH
      "Where scripts/setup_meshlab2025.sh keeps MeshLab 2025.07's sources (meshlab/) and build (build/)")
  set(GI_MESHLAB_SOURCE_DIR "${GI_MESHLAB2025_HOME}/meshlab/src" CACHE PATH
      "MeshLab 2025.07's src/ folder (holds common/ and vcglib/)")
  set(GI_MESHLAB_DISTRIB_DIR "${GI_MESHLAB2025_HOME}/build/src/distrib" CACHE PATH
      "MeshLab 2025.07 build's distrib/ folder (meshlab, libmeshlab-common.so, plugins/)")
  if(NOT EXISTS "${GI_MESHLAB_SOURCE_DIR}/common/plugins/interfaces/filter_plugin.h")
    message(FATAL_ERROR "MeshLab 2025.07 sources not found in ${GI_MESHLAB_SOURCE_DIR}: "
                        "run scripts/setup_meshlab2025.sh first, or set GI_MESHLAB_SOURCE_DIR")
  endif()
  file(STRINGS "${GI_MESHLAB_SOURCE_DIR}/../ML_VERSION" _ml_version LIMIT_COUNT 1)
  if(NOT _ml_version STREQUAL "2025.07")
    message(FATAL_ERROR "${GI_MESHLAB_SOURCE_DIR} is MeshLab '${_ml_version}', not 2025.07")
  endif()
  set(MESHLAB_LIB_DIR "${GI_MESHLAB_DISTRIB_DIR}")
  set(_ml_include "${GI_MESHLAB_SOURCE_DIR}" "${GI_MESHLAB_SOURCE_DIR}/vcglib")
  # MeshLab checks that a plugin was built for its own version and scalar type.
  set(_ml_defs MESHLAB_SCALAR=float MESHLAB_VERSION=2025.07 GI_MESHLAB_2025)
  set(_ml_qt Core Gui Widgets OpenGL Xml Network)
  set(_ml_plugins "${GI_MESHLAB_DISTRIB_DIR}/plugins")
else()
  message(FATAL_ERROR "GI_MESHLAB_TARGET must be 2020.09 or 2025.07, not '${GI_MESHLAB_TARGET}'")
endif()

find_library(MESHLAB_COMMON_LIB meshlab-common PATHS "${MESHLAB_LIB_DIR}" NO_DEFAULT_PATH)
if(NOT MESHLAB_COMMON_LIB)
  message(FATAL_ERROR "libmeshlab-common.so not found in ${MESHLAB_LIB_DIR}: "
                      "install the meshlab package (2020.09) or run scripts/setup_meshlab2025.sh (2025.07)")
endif()
find_package(Qt5 REQUIRED COMPONENTS ${_ml_qt})
find_package(Eigen3 REQUIRED)
find_package(GLEW REQUIRED)
find_package(OpenGL REQUIRED)

add_library(meshlab_common INTERFACE)
add_library(meshlab::common ALIAS meshlab_common)
target_include_directories(meshlab_common SYSTEM INTERFACE ${_ml_include} ${EIGEN3_INCLUDE_DIR})
target_compile_definitions(meshlab_common INTERFACE ${_ml_defs})
list(TRANSFORM _ml_qt PREPEND "Qt5::")
target_link_libraries(meshlab_common INTERFACE "${MESHLAB_COMMON_LIB}" ${_ml_qt} GLEW::GLEW OpenGL::GL)

set(GI_PLUGIN_INSTALL_DIR "${_ml_plugins}" CACHE PATH "Where MeshLab loads plugins from")
message(STATUS "MeshLab plugins for MeshLab ${GI_MESHLAB_TARGET} (libmeshlab-common: ${MESHLAB_COMMON_LIB})")

# gi_add_plugin(name sources...): a MeshLab filter plugin module libname.so
function(gi_add_plugin name)
  add_library(${name} MODULE ${ARGN})
  set_target_properties(${name} PROPERTIES AUTOMOC ON PREFIX "lib"
    LIBRARY_OUTPUT_DIRECTORY "${PROJECT_BINARY_DIR}/plugins")
  target_link_libraries(${name} PRIVATE gi_meshlab_bridge)
  target_compile_options(${name} PRIVATE ${GI_WARNINGS})
  install(TARGETS ${name} LIBRARY DESTINATION "${GI_PLUGIN_INSTALL_DIR}" COMPONENT plugins)
endfunction()

# Imported target meshlab::common: the headers of MeshLab 2020.09 (src/common and
# vcglib from Debian's source package, fetched by scripts/setup.sh) and the
# installed libmeshlab-common.so.
set(MESHLAB_SDK_DIR "${PROJECT_SOURCE_DIR}/.deps/meshlab-sdk" CACHE PATH "MeshLab 2020.09 SDK (src/common + vcglib)")
set(MESHLAB_LIB_DIR "/usr/lib/${CMAKE_LIBRARY_ARCHITECTURE}/meshlab" CACHE PATH "Folder of libmeshlab-common.so and plugins/")
if(NOT EXISTS "${MESHLAB_SDK_DIR}/src/common/interfaces.h")
  message(FATAL_ERROR "MeshLab SDK not found in ${MESHLAB_SDK_DIR}: run scripts/setup.sh first")
endif()
find_library(MESHLAB_COMMON_LIB meshlab-common PATHS "${MESHLAB_LIB_DIR}" NO_DEFAULT_PATH)
if(NOT MESHLAB_COMMON_LIB)
  message(FATAL_ERROR "libmeshlab-common.so not found in ${MESHLAB_LIB_DIR}: install the meshlab package")
endif()
find_package(Qt5 REQUIRED COMPONENTS Core Gui Widgets OpenGL Xml XmlPatterns)
find_package(Eigen3 REQUIRED)
find_package(GLEW REQUIRED)
find_package(OpenGL REQUIRED)

add_library(meshlab_common INTERFACE)
add_library(meshlab::common ALIAS meshlab_common)
target_include_directories(meshlab_common SYSTEM INTERFACE
  "${MESHLAB_SDK_DIR}/src" "${MESHLAB_SDK_DIR}/vcglib" ${EIGEN3_INCLUDE_DIR})
target_compile_definitions(meshlab_common INTERFACE MESHLAB_SCALAR=float)
target_link_libraries(meshlab_common INTERFACE "${MESHLAB_COMMON_LIB}"
  Qt5::Core Qt5::Gui Qt5::Widgets Qt5::OpenGL Qt5::Xml Qt5::XmlPatterns GLEW::GLEW OpenGL::GL)

# Debian's MeshLab loads plugins from <prefix of its binary>/lib/<arch>/meshlab/plugins,
# i.e. /usr/lib/<arch>/meshlab/plugins: install there whatever CMAKE_INSTALL_PREFIX is.
set(GI_PLUGIN_INSTALL_DIR "${MESHLAB_LIB_DIR}/plugins" CACHE PATH "Where MeshLab loads plugins from")

# gi_add_plugin(name sources...): a MeshLab filter plugin module libname.so
function(gi_add_plugin name)
  add_library(${name} MODULE ${ARGN})
  set_target_properties(${name} PROPERTIES AUTOMOC ON PREFIX "lib"
    LIBRARY_OUTPUT_DIRECTORY "${PROJECT_BINARY_DIR}/plugins")
  target_link_libraries(${name} PRIVATE gi_meshlab_bridge)
  target_compile_options(${name} PRIVATE ${GI_WARNINGS})
  install(TARGETS ${name} LIBRARY DESTINATION "${GI_PLUGIN_INSTALL_DIR}" COMPONENT plugins)
endfunction()

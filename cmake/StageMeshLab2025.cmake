# A staged MeshLab 2025.07 in <build>/stage: a copy of the meshlab executable
# (a copy, not a link: MeshLab looks for plugins/ and shaders/ next to the real
# path of its binary) with links to MeshLab's shaders and PLY reader and to our
# plugins. libmeshlab-common.so is found through the copy's run path (the
# MeshLab build folder). Nothing is written into the MeshLab build.
set(GI_STAGE_DIR "${PROJECT_BINARY_DIR}/stage")
set(_our_plugins filter_ambient filter_radiosity filter_photonmap filter_reference filter_raytrace)
set(_cmds
  COMMAND ${CMAKE_COMMAND} -E make_directory "${GI_STAGE_DIR}/bin/plugins"
  COMMAND ${CMAKE_COMMAND} -E copy_if_different "${GI_MESHLAB_DISTRIB_DIR}/meshlab" "${GI_STAGE_DIR}/bin/"
  COMMAND ${CMAKE_COMMAND} -E create_symlink "${GI_MESHLAB_DISTRIB_DIR}/shaders" "${GI_STAGE_DIR}/bin/shaders"
  COMMAND ${CMAKE_COMMAND} -E create_symlink "${GI_MESHLAB_DISTRIB_DIR}/plugins/libio_base.so"
          "${GI_STAGE_DIR}/bin/plugins/libio_base.so")
foreach(p ${_our_plugins})
  list(APPEND _cmds COMMAND ${CMAKE_COMMAND} -E create_symlink "$<TARGET_FILE:${p}>" "${GI_STAGE_DIR}/bin/plugins/lib${p}.so")
endforeach()
add_custom_target(stage_meshlab ALL ${_cmds}
  DEPENDS ${_our_plugins}
  COMMENT "Staging MeshLab ${GI_MESHLAB_TARGET} with our plugins in ${GI_STAGE_DIR}/bin")

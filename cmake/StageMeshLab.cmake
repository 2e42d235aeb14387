# A staged MeshLab in <build>/stage: copies of meshlab and meshlabserver (copies,
# not links: Qt resolves the real path to find <prefix>/lib/.../meshlab) next to
# a plugin folder linking the system plugins plus ours. Nothing goes into /usr.
set(GI_STAGE_DIR "${PROJECT_BINARY_DIR}/stage")
set(_stage_lib "${GI_STAGE_DIR}/lib/${CMAKE_LIBRARY_ARCHITECTURE}/meshlab")
set(_our_plugins filter_ambient filter_radiosity filter_photonmap filter_reference filter_raytrace)
set(_cmds
  COMMAND ${CMAKE_COMMAND} -E make_directory "${GI_STAGE_DIR}/bin" "${_stage_lib}/plugins"
  COMMAND ${CMAKE_COMMAND} -E copy_if_different /usr/bin/meshlabserver /usr/bin/meshlab "${GI_STAGE_DIR}/bin/"
  COMMAND ${CMAKE_COMMAND} -E create_symlink "${MESHLAB_COMMON_LIB}" "${_stage_lib}/libmeshlab-common.so"
  COMMAND ${CMAKE_COMMAND} -DSRC=${MESHLAB_LIB_DIR}/plugins -DDST=${_stage_lib}/plugins
          -P "${PROJECT_SOURCE_DIR}/cmake/link_system_plugins.cmake")
foreach(p ${_our_plugins})
  list(APPEND _cmds COMMAND ${CMAKE_COMMAND} -E create_symlink "$<TARGET_FILE:${p}>" "${_stage_lib}/plugins/lib${p}.so")
endforeach()
add_custom_target(stage_meshlab ALL ${_cmds}
  DEPENDS ${_our_plugins}
  COMMENT "Staging meshlab + meshlabserver with our plugins in ${GI_STAGE_DIR}")
configure_file("${PROJECT_SOURCE_DIR}/scripts/mlx-run.in" "${PROJECT_BINARY_DIR}/mlx-run" @ONLY
  FILE_PERMISSIONS OWNER_READ OWNER_WRITE OWNER_EXECUTE GROUP_READ GROUP_EXECUTE WORLD_READ WORLD_EXECUTE)

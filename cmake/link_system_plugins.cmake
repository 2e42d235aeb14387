# Links every system MeshLab plugin from SRC into DST (ours are linked separately).
file(GLOB _plugins "${SRC}/*.so")
foreach(p ${_plugins})
  get_filename_component(n "${p}" NAME)
  if(NOT n MATCHES "^libfilter_(ambient|radiosity|photonmap|reference)\\.so$")
    file(CREATE_LINK "${p}" "${DST}/${n}" SYMBOLIC)
  endif()
endforeach()

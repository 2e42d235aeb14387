#include "gi_output.h"

#include "gi/refine.h"
#include "mesh_io.h"

namespace gi {

void writeResultPly(const std::string& path, const Scene& input, const MeshAttributes& inputAttrs,
                    const std::vector<glm::vec3>& fileNormals, const FilterResult& r,
                    const std::vector<LayerRange>& layers) {
  const Scene& out = r.refined ? r.refined->scene : input;
  MeshAttributes attrs = r.refined ? refineAttributes(inputAttrs, *r.refined) : inputAttrs;
  if (!r.faceQuality.empty()) attrs.faceQuality = r.faceQuality;
  if (!r.faceColor.empty()) {
    attrs.faceColor.clear();
    for (const Rgb8& c : r.faceColor) attrs.faceColor.push_back({c.r, c.g, c.b});
  }
  io::PlyExtras extras;
  extras.normals = !r.vertexNormal.empty() ? r.vertexNormal : r.refined ? std::vector<glm::vec3>() : fileNormals;
  extras.attributes = r.attributes;
  if (!r.refined)
    for (const LayerRange& l : layers) extras.layers.push_back({l.name, l.faceCount});
  io::writePly(path, out, attrs, r.vertexQuality, r.vertexColor, extras);
}

std::vector<std::string> writeLayerPlys(const std::string& outputPly, const FilterResult& r) {
  std::vector<std::string> paths;
  for (const FilterLayer& L : r.layers) {
    io::PlyExtras extras;
    extras.normals = L.normals;
    paths.push_back(layerPath(outputPly, L.name));
    io::writePly(paths.back(), L.mesh, MeshAttributes{}, L.quality, L.color, extras);
  }
  return paths;
}

}  // namespace gi

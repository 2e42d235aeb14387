#include "gi_output.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <set>
#include <string>
#include <vector>

#include "gi/refine.h"
#include "mesh_io.h"

namespace gi {

void writeResultPly(const std::string& path, const Scene& input, const MeshAttributes& inputAttrs,
                    const std::vector<glm::vec3>& fileNormals, const FilterResult& r,
                    const std::vector<LayerRange>& layers, const std::vector<VertexAttribute>& earlier,
                    const std::vector<glm::dvec3>& filePoints) {
  const Scene& out = r.refined ? r.refined->scene : input;
  MeshAttributes attrs = r.refined ? refineAttributes(inputAttrs, *r.refined) : inputAttrs;
  if (!r.faceQuality.empty()) attrs.faceQuality = r.faceQuality;
  if (!r.faceColor.empty()) {
    attrs.faceColor.clear();
    for (const Rgb8& c : r.faceColor) attrs.faceColor.push_back({c.r, c.g, c.b});
  }
  io::PlyExtras extras;
  extras.normals = !r.vertexNormal.empty() ? r.vertexNormal
                   : r.refined             ? refineVertexNormals(fileNormals, *r.refined)
                                           : fileNormals;
  extras.attributes = r.attributes;
  if (!r.refined && filePoints.size() == input.vertexCount()) extras.positions = filePoints;
  if (!r.refined) {
    // The property names an attribute is written as (NAME, or NAME_x, _y, _z).
    auto names = [](const VertexAttribute& a) {
      return a.components == 1 ? std::vector<std::string>{a.name}
                               : std::vector<std::string>{a.name + "_x", a.name + "_y", a.name + "_z"};
    };
    std::set<std::string> taken;
    for (const VertexAttribute& a : r.attributes)
      for (const std::string& n : names(a)) taken.insert(n);
    for (const VertexAttribute& a : earlier) {
      // The earlier quality's error bars and path counts describe the
      // quality this result replaces (a reference's StdError beside
      // radiosity's quality was read by the error map as radiosity's; an
      // outside review): not carried.
      if (a.name == "StdError" || a.name == "StdErrorH" || a.name == "Paths") continue;
      const bool finite = std::all_of(a.values.begin(), a.values.end(), [](float x) { return std::isfinite(x); });
      const std::vector<std::string> own = names(a);
      // Not a name the result writes (as NAME or NAME_x...), nor one of the
      // writer's own properties (quality, alpha, ...); not one holding NaN,
      // as a hostile file may.
      const bool free = std::none_of(own.begin(), own.end(), [&](const std::string& n) {
        return taken.count(n) || io::plyVertexPropertyOfItsOwn(n);
      });
      if (!free || !finite || a.values.size() != size_t(a.components) * input.vertexCount()) continue;
      taken.insert(own.begin(), own.end());
      extras.attributes.push_back(a);
    }
  }
  if (!r.refined || layers.size() < 2) {
    for (const LayerRange& l : layers) extras.layers.push_back({l.name, l.faceCount});
    io::writePly(path, out, attrs, r.vertexQuality, r.vertexColor, extras);
    return;
  }
  // Refined with layers: the faces grouped by the layer of their input face
  // (refinement appends new faces at the end), so that the file still
  // records each layer's faces and a later run reads them as layers again.
  std::vector<uint32_t> layerOf(input.faceCount(), 0);
  for (uint32_t L = 0; L < layers.size(); ++L)
    for (size_t f = layers[L].faceOffset; f < layers[L].faceOffset + layers[L].faceCount && f < layerOf.size(); ++f)
      layerOf[f] = L;
  const RefinedMesh& m = *r.refined;
  std::vector<uint32_t> order(m.sourceFace.size());
  for (uint32_t f = 0; f < order.size(); ++f) order[f] = f;
  std::stable_sort(order.begin(), order.end(),
                   [&](uint32_t a, uint32_t b) { return layerOf[m.sourceFace[a]] < layerOf[m.sourceFace[b]]; });
  std::vector<size_t> count(layers.size(), 0);
  for (uint32_t f : order) ++count[layerOf[m.sourceFace[f]]];
  for (size_t L = 0; L < layers.size(); ++L) extras.layers.push_back({layers[L].name, count[L]});
  Scene grouped = out;
  auto permute = [&](auto& v) {
    if (v.size() != order.size()) return;
    auto copy = v;
    for (size_t k = 0; k < order.size(); ++k) v[k] = copy[order[k]];
  };
  permute(grouped.triangles);
  permute(attrs.faceColor);
  permute(attrs.faceQuality);
  permute(attrs.faceSelected);
  io::writePly(path, grouped, attrs, r.vertexQuality, r.vertexColor, extras);
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

uint64_t fnv1a(uint64_t h, const void* bytes, size_t n) {
  const unsigned char* p = static_cast<const unsigned char*>(bytes);
  for (size_t i = 0; i < n; ++i) h = (h ^ p[i]) * 1099511628211ull;
  return h;
}

std::string hex64(uint64_t h) {
  char b[17];
  std::snprintf(b, sizeof b, "%016llx", (unsigned long long)h);
  return b;
}

std::string fileDigest(const std::string& path) {
  // Only a regular file: a pipe's open waits for a writer, and its bytes,
  // read here, would be gone for the filter (a batch lists a FIFO as a mesh
  // that fails as such).
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) return "";
  std::ifstream in(path, std::ios::binary);
  if (!in) return "";
  uint64_t h = kFnvOffset, size = 0;
  std::vector<char> buf(1 << 16);
  while (in) {
    in.read(buf.data(), std::streamsize(buf.size()));
    const size_t got = size_t(in.gcount());
    h = fnv1a(h, buf.data(), got), size += got;
  }
  if (in.bad()) return "";
  return std::to_string(size) + ":" + hex64(h);
}

const std::string& programIdentity() {
  static const std::string id = [] {
    const std::string digest = fileDigest("/proc/self/exe");
    return std::string(GI_VERSION) + (digest.empty() ? std::string() : " " + digest);
  }();
  return id;
}

}  // namespace gi

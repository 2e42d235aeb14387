// The benchmark's reference AO with a choice of vertex normals:
//   ao_reference MESH OUT.ply RAYS_PER_VERTEX SEED angle|area  ->  JSON on stdout
// Our engine computes vertex normals as angle-weighted means of the face
// normals (docs/design.md, "Conventions"); MeshLab's "Ambient Occlusion"
// recomputes them as area-weighted means (vcglib's
// UpdateNormal::PerVertexNormalizedPerFaceNormalized: the sum of the faces'
// cross products). AO depends on the normal (the cosine lobe's axis), so
// each method is measured against a reference with its own normals. The
// estimator is the per-vertex one (exact mode) at a high ray count.
#include <cstdio>
#include <cstdlib>
#include <string>

#include "gi/ambient.h"
#include "gi/raycaster.h"
#include "mesh_io.h"

using namespace gi;

int main(int argc, char** argv) {
  if (argc < 6) {
    std::fprintf(stderr, "usage: ao_reference MESH OUT.ply RAYS_PER_VERTEX SEED angle|area\n");
    return 2;
  }
  try {
    io::LoadedMesh mesh = io::loadMesh(argv[1]);
    Scene& s = mesh.scene;
    const std::string normals = argv[5];
    if (normals == "area") {
      s.vertexNormals.assign(s.vertexCount(), glm::vec3(0.f));
      for (const auto& t : s.triangles) {
        const glm::vec3 n = glm::cross(s.positions[t.y] - s.positions[t.x], s.positions[t.z] - s.positions[t.x]);
        for (int k = 0; k < 3; ++k) s.vertexNormals[t[k]] += n;
      }
      for (auto& n : s.vertexNormals) n = glm::length(n) > 0.f ? glm::normalize(n) : glm::vec3(0.f);
    } else if (normals == "angle") {
      s.vertexNormals.clear();  // computeAmbient computes the angle-weighted ones
    } else {
      throw std::invalid_argument("normals must be angle or area, not " + normals);
    }
    AmbientOptions o;
    o.raysPerVertex = std::atoi(argv[3]);
    o.seed = uint32_t(std::strtoul(argv[4], nullptr, 10));
    o.estimator = AOEstimator::PerVertex;
    const auto caster = makeEmbreeCaster(s, BatchMode::Single);
    const AmbientResult r = computeAmbient(s, *caster, o);
    io::writePly(argv[2], s, mesh.attrs, r.value, {}, {{}, {{"StdError", 1, r.stdError}}});
    std::printf("{\"vertices\": %zu, \"rays_per_vertex\": %d, \"seed\": %u, \"normals\": \"%s\", \"seconds\": %.6g, "
                "\"rms_error_estimate\": %.6g}\n",
                s.vertexCount(), o.raysPerVertex, o.seed, normals.c_str(), r.stats.get("seconds"),
                r.stats.get("rms_error_estimate"));
  } catch (const std::exception& e) {
    std::fprintf(stderr, "ao_reference: %s\n", e.what());
    return 1;
  }
  return 0;
}

// The PLY file a run of `gi` writes (one filter on one mesh, or each mesh
// of `gi batch`).
#pragma once
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "gi/filter_run.h"

namespace gi {

// The input mesh (or its refinement) with the result's properties: what the
// result leaves alone keeps the input's values (colours, face quality and
// the file's own normals, which the engine does not use); a scene of two or
// more layers records them in the file (io::PlyExtras::layers), unless the
// result refined the mesh. The input's per-vertex attributes (what an
// earlier filter left: Reference, Radiosity, ...) stay beside the result's
// where it writes none of that name, as they stay on a MeshLab layer (a
// chain reference -> radiosity -> error map lost the reference on the way;
// an outside audit); a refined mesh has other vertices and keeps none, and
// the earlier quality's StdError, StdErrorH and Paths are not carried.
// `filePoints`: the input's positions as read (io::LoadedMesh::points),
// written as they are unless the result refined the mesh.
void writeResultPly(const std::string& path, const Scene& input, const MeshAttributes& inputAttrs,
                    const std::vector<glm::vec3>& fileNormals, const FilterResult& r,
                    const std::vector<LayerRange>& layers = {}, const std::vector<VertexAttribute>& earlier = {},
                    const std::vector<glm::dvec3>& filePoints = {});

// Each new layer of the result (photon mapping's photons) as a PLY beside the
// output, at gi::layerPath (out.ply -> out.Photons.ply): points, colour,
// quality, normals. Returns the paths written.
std::vector<std::string> writeLayerPlys(const std::string& outputPly, const FilterResult& r);

// FNV-1a, 64 bits: the hash `gi` keys its files and jobs with (a batch's
// resume hash, its results' digests, the ranks' job under mpirun).
constexpr uint64_t kFnvOffset = 1469598103934665603ull;
uint64_t fnv1a(uint64_t h, const void* bytes, size_t n);
std::string hex64(uint64_t h);  // 16 hex digits
inline std::string hashText(const std::string& s) { return hex64(fnv1a(kFnvOffset, s.data(), s.size())); }
// A file as it is: its size and the hash of its bytes ("" if it cannot be
// read). A resumed batch takes a result as done only where its summary
// records the same: one truncated or edited by hand since was counted as
// done (an outside audit).
std::string fileDigest(const std::string& path);

// What identifies this program's results: its version and the digest of
// its own executable, read once. A rebuild may compute otherwise (the
// version alone never changed, and `--cache` and `gi batch` reused results
// of an older build; a review).
const std::string& programIdentity();

}  // namespace gi

// Adaptive mesh refinement for radiosity: conforming red-green subdivision of
// a triangle mesh (Bank, Sherman and Weiser 1983) and the criterion that says
// where a radiosity solution needs smaller patches.
//
// Subdivision. A face to refine is split 1 -> 4 at its edge midpoints (red).
// A neighbour left with one split edge is bisected 1 -> 2 from that edge's
// midpoint to the opposite vertex (green); with two or three split edges it
// is made red too, and this closure is iterated. A green face is never split
// again: when it has to be refined (or a neighbour splits one of its edges)
// the green pair is removed and its parent is red-split instead. Hence every
// face is similar to an input face or a bisected half of one (angles stay
// bounded: no slivers), and because each split edge is split on both sides
// through one shared midpoint, a conforming input stays conforming (no
// T-junctions; a closed mesh stays closed). Edges are identified by their
// vertex indices: separate sheets that merely touch are refined separately.
#pragma once
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "gi/params.h"
#include "gi/raycaster.h"
#include "gi/scene.h"
#include "gi/scene_setup.h"
#include "gi/sky.h"

namespace gi {

// The mesh after refinement, with the provenance of every element.
struct RefinedMesh {
  Scene scene;                          // faces inherit rho, emission, material and ior
  std::vector<uint32_t> sourceFace;     // per face: its face in the input scene
  std::vector<uint8_t> depth;           // per face: red splits since its input face
  std::vector<glm::uvec2> vertexParents;  // per vertex: the edge it is the midpoint of ({v, v}: an input vertex)
  size_t inputVertices = 0;             // vertices [0, inputVertices) are the input's, same order
};

// Red-green subdivision state (keeps the green parents and the shared edge
// midpoints between calls, so refinement can go on level after level).
class MeshRefiner {
 public:
  explicit MeshRefiner(const Scene& input);
  ~MeshRefiner();
  MeshRefiner(MeshRefiner&&) noexcept;
  MeshRefiner& operator=(MeshRefiner&&) noexcept;

  const RefinedMesh& mesh() const;
  // Face count after refine(faces), without changing anything (for budgets).
  size_t faceCountAfter(const std::vector<uint32_t>& faces) const;
  // Red-splits `faces` (indices into mesh().scene) and closes the mesh
  // conformingly. Returns the number of faces added.
  size_t refine(const std::vector<uint32_t>& faces);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

struct RefineOptions {
  int maxDepth = 3;             // levels; faces at this depth are not chosen (the conformity closure
                                // may split a neighbour once more where input triangles differ in size)
  int maxPatches = 200000;      // never more faces than this
  double threshold = 0.1;       // relative jump of the reflected radiosity across an edge
  double shadowThreshold = 0.3; // difference of a light's visibility between a face's vertices (emitters, sun)
  int visibilityRays = 64;      // shadow rays per vertex for that visibility
  double creaseDegrees = 30.0;  // no B-jump test across sharper creases (a true discontinuity)
  uint32_t seed = 0;
  // The refine_* parameters of the radiosity filter (after its "refine"
  // switch); fromParams also reads the filter's "seed".
  static std::vector<ParamSpec> specs();
  static RefineOptions fromParams(const ParamValues& v);
};

// Per vertex: the fraction of shadow rays to power-sampled emitter points
// (those whose emitting side faces the vertex) that arrive; -1 where no
// emitter faces the vertex. Deterministic per (vertex, ray, seed).
std::vector<float> emitterVisibility(const Scene& s, const RayCaster& caster, int rays, uint32_t seed);

// Per vertex: the fraction of `rays` directions uniform in the sun's cone
// (those above the vertex's tangent plane) in which a ray from the vertex
// leaves the scene; -1 where the whole cone lies below that plane, and for
// every vertex without a sun. Deterministic per (vertex, ray, seed). The
// sun's shadow is the sharpest a scene lit from outside has, and on a
// coarse mesh the B jump test misses one that dims a patch by less than
// the jump threshold (a pole's shadow across a floor patch).
std::vector<float> sunVisibility(const Scene& s, const RayCaster& caster, const SkySun& o, int rays, uint32_t seed);

// Faces that need refinement, most needing first. B jumps: across an edge
// between faces less than creaseDegrees apart, |R_i - R_j| / max(R_i, R_j,
// 1% of the area-weighted mean R) > threshold (R = luminance of B - E, the
// reflected radiosity); or, given per-vertex values (else pass {}), between
// the patch's R and the mean of its corners' R (the error of the displayed
// linear interpolation), with the same measure and threshold. Shadow
// boundaries: for one of the lights (`visibility`: per light, per vertex,
// as emitterVisibility and sunVisibility give; empty ones skipped), max -
// min of the vertices' visibility > shadowThreshold. Priority = area x the
// larger excess ratio. Faces already at maxDepth are left out.
struct RefineMarks {
  std::vector<uint32_t> faces;  // by decreasing priority (ties: by index)
  size_t byJump = 0, byShadow = 0;
};
RefineMarks markForRefinement(const Scene& s, const std::vector<glm::vec3>& B, const std::vector<glm::vec3>& Bvertex,
                              const std::vector<std::vector<float>>& visibility, const std::vector<uint8_t>& depth,
                              const RefineOptions& opt);

// The attributes of the input mesh carried to the refined one: face colour,
// quality and selection from the source face; vertex colours of new vertices
// interpolated (in linear light) between their parents; a new vertex
// selected where both its parents are.
MeshAttributes refineAttributes(const MeshAttributes& a, const RefinedMesh& m);
// Vertex normals of the input carried to the refined mesh: a midpoint takes
// the normalised sum of its edge's two ends (an input vertex keeps its own;
// empty stays empty).
std::vector<glm::vec3> refineVertexNormals(const std::vector<glm::vec3>& n, const RefinedMesh& m);

}  // namespace gi

// Internal to the hierarchical solver (hierarchical.cpp): the cluster tree
// over the triangles, its nodes' quadrature points and the link form
// factors with their visibility rays (hierarchy_nodes.cpp).
#pragma once
#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include "gi/raycaster.h"
#include "gi/scene.h"

namespace gi::hierarchy {

// A node of the cluster tree: a triangle (leaf) or the triangles of
// order[first, first + count). Nodes are stored in preorder, so a parent's
// index is below its children's (push: forward loop; pull: backward loop).
struct Node {
  glm::dvec3 c{0.0};   // bounding-sphere centre (bbox centre)
  double r = 0;        // bounding-sphere radius (half the bbox diagonal)
  double A = 0;        // area
  uint32_t first = 0, count = 0;
  uint32_t left = 0, right = 0;  // children (leaves: 0)
  uint32_t parent = 0;
  glm::vec3 lo{0.f}, hi{0.f};    // bbox (plane culling)
  bool planar = false;           // all its triangles in one plane (x0, n), facing n
  glm::dvec3 x0{0.0};
  glm::vec3 n{0.f};
  glm::vec3 axis{0.f};           // normal cone: unit axis and the cosine of its half-angle
  float coneCos = 1.f;
  bool leaf() const { return count == 1; }
};

struct Link {
  uint32_t p, q;  // receiver, source
  float F;        // area-mean form factor F_pq; with samples: F_pq per passing sample
  uint32_t samples = kAreaMean;  // bit sourceBit(j): a ray to source point j passed (its R is gathered)
  static constexpr uint32_t kAreaMean = 0x80000000u;  // no samples: gather the source's area mean
  static constexpr uint32_t kProbed = 0x40000000u;    // its receiver's points all see the source alike
  static constexpr uint32_t kSampleBits = 0xffffu;    // the bits of samples that name rays
  bool areaMean() const { return (samples & kAreaMean) != 0; }
};

struct Tree {
  std::vector<Node> nodes;
  std::vector<uint32_t> order;      // triangle of each leaf position
  std::vector<double> Acum;         // prefix sums of the leaves' areas in `order`
  std::vector<uint32_t> leafOf;     // node of each face (kNoHit: unusable)
  int depth = 0;
};

struct Geometry {
  const Scene& s;
  std::vector<double> A;
  std::vector<glm::vec3> n;  // unit face normals
  std::vector<glm::dvec3> centroid;
  // Partly buried triangles (gi/patch_seen.h), or null: each triangle's
  // seen share and the points found open on it.
  const std::vector<float>* seen = nullptr;
  const std::vector<std::vector<glm::vec3>>* seenPoints = nullptr;
};

// The cluster tree over the triangles: a median split of the centroids
// along the longest axis, nodes in preorder, planar nodes and normal cones.
Tree buildTree(const Geometry& g);

// The node's 16 quadrature points, stratified by area (faces: the triangle
// under each point, when asked for).
constexpr int kPoints = 16;
void nodePoints(const Geometry& g, const Tree& t, const Node& nd, glm::dvec3 x[kPoints], glm::vec3 n[kPoints],
                uint32_t faces[kPoints] = nullptr);

// Visibility ray k of a link pairs point i of the receiver with point j of
// the source; both point sets are walked in different orders (the first
// kPoints source points are all of them, each once).
inline int rayReceiverPoint(int k) { return k % kPoints; }
inline int raySourcePoint(int k) { return (5 * k + 3 + k / kPoints) % kPoints; }
// The bit of Link::samples that names source point j: the k < kPoints with
// raySourcePoint(k) = j (5 * 13 = 1 modulo 16), so that with up to 16 rays
// bit k is ray k's.
inline int sourceBit(int j) { return (13 * (j + kPoints - 3)) % kPoints; }

// True when no point of the box lies strictly in front of the plane (x0, n):
// nothing in the box can exchange light with the front of that plane.
bool boxBehind(const Node& box, const glm::dvec3& x0, const glm::vec3& n);

// F_pq of a link (and which of its rays passed, for a cluster source): see
// hierarchy_nodes.cpp.
// A node's points (nodePoints) kept for reuse by one thread: the receiver's
// in one slot (links come grouped by receiver), sources in a direct-mapped
// table. The points are the node's alone, so reuse changes no bit; it saves
// their computation's random reads (the tree's area table, the triangles'
// corners), which took a fifth of a 1M-triangle run.
struct NodePointSet {
  uint32_t node = 0xffffffffu;
  glm::dvec3 x[kPoints];
  glm::vec3 n[kPoints];
};

// A receiver's points on the part of it the scene sees (Geometry::seen):
// a point on a partly buried triangle moves to one of the points found open
// on it (each triangle's in turn), a point on a wholly buried one takes the
// place of the next point kept. What a link brings is then taken on the
// seen part, as the flat solvers' rows are (for a triangle, the mean over
// its seen part; a cluster's points keep the weights their triangles' whole
// areas gave them, so its mean is the seen part's only roughly); the points anywhere on the
// triangle, their passing share divided by the seen share, made a ratio of
// two estimates from different points (a floor triangle a few percent seen
// beside the Cornell box's short block: 0.71 where the floor's brightest
// patch seen whole is 0.54). False, the points unchanged, where no point
// lies on a seen part.
bool moveToSeenParts(const Geometry& g, const uint32_t faces[kPoints], NodePointSet& e);

class NodePointCache {
 public:
  explicit NodePointCache(size_t slots = 4096) : sources_(slots) {}
  const NodePointSet& receiver(const Geometry& g, const Tree& t, uint32_t k) {
    if (receiver_.node != k) {
      uint32_t faces[kPoints];
      nodePoints(g, t, t.nodes[k], receiver_.x, receiver_.n, faces);
      moveToSeenParts(g, faces, receiver_);
      receiver_.node = k;
    }
    return receiver_;
  }
  const NodePointSet& source(const Geometry& g, const Tree& t, uint32_t k) {
    NodePointSet& e = sources_[k % sources_.size()];
    if (e.node != k) {
      nodePoints(g, t, t.nodes[k], e.x, e.n);
      e.node = k;
    }
    return e;
  }

 private:
  NodePointSet receiver_;
  std::vector<NodePointSet> sources_;
};

// The visibility ray between receiver point i and source point j of a link
// (each lifted off its surface by the ray offset); false where that pair
// exchanges nothing (either faces away from the other).
bool linkRay(const NodePointSet& pp, const NodePointSet& pq, int i, int j, float eps, Ray& r);

// Whether the 16 points of receiver p see source q unlike: a ray from each
// to a point of q it exchanges light with passes for some and not for
// others, or some exchange light with no point of q (rays counted in
// `rays`).
bool linkPartlyVisible(const Geometry& g, const Tree& t, const RayCaster& caster, uint32_t p, uint32_t q, float eps,
                       uint64_t& rays, NodePointCache& points);

void linkFormFactor(const Geometry& g, const Tree& t, const RayCaster& caster, Link& link, int linkRays,
                    bool unoccluded, float eps, uint64_t& rays, NodePointCache& points);

// The fraction G of each triangle's cosine-weighted hemisphere that meets
// the front of a (usable) triangle, counted with `rays` stratified rays
// from points on it (origins and directions as the Monte Carlo form
// factors draw them): what its row of form factors sums to. 1 exactly
// where every ray hits; unusable faces: 0.
std::vector<float> rowClosures(const Geometry& g, const RayCaster& caster, int rays, uint32_t seed, float eps,
                               uint64_t& cast);

}  // namespace gi::hierarchy

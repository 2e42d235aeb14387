#include "gi/open_space.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <map>
#include <stdexcept>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_invoke.h>


namespace gi {

namespace {

// The axis of a box's longest side: the trees below split there.
int longestAxis(const glm::vec3& size) { return size.x >= size.y && size.x >= size.z ? 0 : size.y >= size.z ? 1 : 2; }

// Depth-first search of a tree of nodes (children left and right; left < 0:
// a leaf) for a leaf where hit(leaf) holds, through the nodes whose bound
// reaches: of two children the higher bound is searched first, so that a
// vertex that is not open meets what refuses it soon.
template <class Node, class Bound, class Reaches, class Hit>
bool searchHighestFirst(const std::vector<Node>& nodes, Bound&& bound, Reaches&& reaches, Hit&& hit) {
  int32_t stack[128];  // a depth-first search holds at most two nodes per level
  int top = 0;
  stack[top++] = 0;
  while (top > 0) {
    const Node& k = nodes[size_t(stack[--top])];
    if (k.left < 0) {
      if (hit(k)) return true;
      continue;
    }
    const int32_t a = k.left, b = k.right;
    const double ha = bound(nodes[size_t(a)]), hb = bound(nodes[size_t(b)]);
    const bool aFirst = ha >= hb;
    const double hLast = aFirst ? hb : ha, hFirst = aFirst ? ha : hb;
    if (reaches(hLast)) stack[top++] = aFirst ? b : a;
    if (reaches(hFirst)) stack[top++] = aFirst ? a : b;
  }
  return false;
}

}  // namespace

struct OpenSpaceTest::Impl {
  struct Face {
    glm::vec3 c;   // centroid
    float r;       // bounding radius around it
    uint32_t face;
  };
  struct Node {
    glm::vec3 clo, chi;       // box of the faces' centroids
    glm::vec3 centre, half;   // box of their corners
    glm::vec3 m{0.f};         // small nodes: their mean face normal (unit; 0: none), and their
    float lo = 0.f, hi = 0.f, rho = 0.f;  // corners x as m.(x - centre) in [lo, hi], |x - centre| across m <= rho
    float maxR;               // their largest radius
    uint32_t begin, end;      // their faces in faces
    int32_t left = -1, right = -1;  // children; -1: a leaf
  };
  static constexpr uint32_t kLeaf = 8, kSlab = 64;
  const Scene& s;
  const std::vector<glm::vec3>& normals;
  float eps;
  std::vector<Face> faces;
  std::vector<Node> nodes;
  std::vector<uint8_t> ringAbove;  // per vertex: one of its own faces blocks (the leaf's test)
  float maxRadius = 0.f;
  Impl(const Scene& sc, const std::vector<glm::vec3>& n, float e) : s(sc), normals(n), eps(e) {}

  // The leaf's test of one face against a vertex at p with normal n: a
  // corner at or above the plane eps/2 over the tangent plane.
  bool rises(uint32_t face, const glm::vec3& p, const glm::vec3& n) const {
    const auto& t = s.triangles[face];
    float h = -HUGE_VALF;
    for (int j = 0; j < 3; ++j) h = std::max(h, glm::dot(n, s.positions[t[j]] - p));
    return !(h < 0.5f * eps);
  }

  // The slab of a small node: its faces' corners along their mean normal,
  // and how far across it they lie from the box's centre (padded for float
  // rounding). Tight where the faces are nearly flat, where the box's own
  // bound is loose by the box's size.
  void slab(Node& node) const {
    glm::dvec3 sum(0.0);
    for (uint32_t i = node.begin; i < node.end; ++i) sum += glm::dvec3(faceNormalUnnormalized(s, faces[i].face));
    const double len = glm::length(sum);
    if (!(len > 0.0) || !std::isfinite(len)) return;
    const glm::dvec3 m = sum / len, c(node.centre);
    double lo = HUGE_VAL, hi = -HUGE_VAL, rho2 = 0.0;
    for (uint32_t i = node.begin; i < node.end; ++i) {
      const auto& t = s.triangles[faces[i].face];
      for (int k = 0; k < 3; ++k) {
        const glm::dvec3 d = glm::dvec3(s.positions[t[k]]) - c;
        const double along = glm::dot(m, d);
        lo = std::min(lo, along);
        hi = std::max(hi, along);
        rho2 = std::max(rho2, glm::dot(d, d) - along * along);
      }
    }
    const double pad = 1e-5 * glm::length(glm::dvec3(node.half)) + 1e-30;
    node.m = glm::vec3(m);
    node.lo = float(lo - pad);
    node.hi = float(hi + pad);
    node.rho = float(std::sqrt(std::max(rho2, 0.0)) + pad);
  }

  // Nodes of the subtree over n faces: its shape depends on n alone (median
  // splits), so every subtree's place in nodes is known before it is built
  // and the two halves can be built at once.
  std::map<uint32_t, uint32_t> subtreeNodes;
  uint32_t nodeCount(uint32_t n) {
    if (n <= kLeaf) return 1;
    const auto it = subtreeNodes.find(n);
    if (it != subtreeNodes.end()) return it->second;
    const uint32_t c = 1 + nodeCount(n / 2) + nodeCount(n - n / 2);
    subtreeNodes.emplace(n, c);
    return c;
  }

  // Fills nodes[id] over faces[b, e) (its subtree in the nodes after it),
  // split at the median centroid along the longest side of the centroids'
  // box; the corners' box and the largest radius come up from the children.
  void build(size_t id, uint32_t b, uint32_t e) {
    glm::vec3 lo(HUGE_VALF), hi(-HUGE_VALF);
    for (uint32_t i = b; i < e; ++i) { lo = glm::min(lo, faces[i].c); hi = glm::max(hi, faces[i].c); }
    Node node;
    node.clo = lo;
    node.chi = hi;
    node.begin = b;
    node.end = e;
    if (e - b <= kLeaf) {
      glm::vec3 clo(HUGE_VALF), chi(-HUGE_VALF);
      float r = 0.f;
      for (uint32_t i = b; i < e; ++i) {
        const auto& t = s.triangles[faces[i].face];
        for (int k = 0; k < 3; ++k) { clo = glm::min(clo, s.positions[t[k]]); chi = glm::max(chi, s.positions[t[k]]); }
        r = std::max(r, faces[i].r);
      }
      node.centre = 0.5f * (clo + chi);
      node.half = 0.5f * (chi - clo) * (1.f + 1e-6f);  // float rounding of centre +- half stays inside
      node.maxR = r;
    } else {
      const int axis = longestAxis(hi - lo);
      const uint32_t mid = b + (e - b) / 2;
      std::nth_element(faces.begin() + b, faces.begin() + mid, faces.begin() + e,
                       [axis](const Face& u, const Face& v) { return u.c[axis] < v.c[axis]; });
      node.left = int32_t(id + 1);
      node.right = int32_t(id + 1 + (mid - b <= kLeaf ? 1 : subtreeNodes.at(mid - b)));  // read only: filled before
      auto buildLeft = [&] { build(size_t(node.left), b, mid); };
      auto buildRight = [&] { build(size_t(node.right), mid, e); };
      if (e - b > 16384) tbb::parallel_invoke(buildLeft, buildRight);
      else { buildLeft(); buildRight(); }
      const Node &l = nodes[size_t(node.left)], &r = nodes[size_t(node.right)];
      const glm::vec3 clo = glm::min(l.centre - l.half, r.centre - r.half), chi = glm::max(l.centre + l.half, r.centre + r.half);
      node.centre = 0.5f * (clo + chi);
      node.half = 0.5f * (chi - clo) * (1.f + 1e-6f);
      node.maxR = std::max(l.maxR, r.maxR);
    }
    if (e - b <= kSlab) slab(node);
    nodes[id] = node;
  }
};

OpenSpaceTest::OpenSpaceTest(const Scene& s, float eps, const std::vector<glm::vec3>& normals,
                             const std::vector<uint8_t>* usable, bool buildTree)
    : impl_(std::make_unique<Impl>(s, normals, eps)) {
  std::vector<uint8_t> own;
  const std::vector<uint8_t>& ok = usableFaces(s, usable, own);
  Impl& m = *impl_;
  for (size_t f = 0; f < ok.size(); ++f)
    if (ok[f]) m.faces.push_back({glm::vec3(0.f), 0.f, uint32_t(f)});
  // Each face's centroid and radius, and which of its corners it refuses: a
  // vertex's own face is within the reach of its rays (the vertex lies in
  // the face's bounding sphere), so if it rises the vertex is not open.
  std::vector<uint8_t> refuses(m.faces.size(), 0);
  tbb::parallel_for(tbb::blocked_range<size_t>(0, m.faces.size(), 1 << 14), [&](const tbb::blocked_range<size_t>& r) {
    for (size_t i = r.begin(); i < r.end(); ++i) {
      Impl::Face& face = m.faces[i];
      const auto& t = s.triangles[face.face];
      const glm::vec3 c = (s.positions[t.x] + s.positions[t.y] + s.positions[t.z]) / 3.f;
      float rad = 0.f;
      for (int k = 0; k < 3; ++k) rad = std::max(rad, glm::length(s.positions[t[k]] - c));
      face.c = c;
      face.r = rad * 1.0001f;
      for (int k = 0; k < 3; ++k)
        if (m.rises(face.face, s.positions[t[k]], normals[t[k]])) refuses[i] |= uint8_t(1u << k);
    }
  });
  m.ringAbove.assign(s.vertexCount(), 0);
  for (size_t i = 0; i < m.faces.size(); ++i) {
    m.maxRadius = std::max(m.maxRadius, m.faces[i].r);
    const auto& t = s.triangles[m.faces[i].face];
    for (int k = 0; k < 3; ++k)
      if (refuses[i] & (1u << k)) m.ringAbove[t[k]] = 1;
  }
  if (buildTree) build();
}

void OpenSpaceTest::build() {
  Impl& m = *impl_;
  if (m.faces.empty() || !m.nodes.empty()) return;
  const uint32_t n = uint32_t(m.faces.size());
  m.nodes.resize(m.nodeCount(n));
  m.build(0, 0, n);
}

OpenSpaceTest::~OpenSpaceTest() = default;

bool OpenSpaceTest::openWithin(uint32_t vertex, float maxDistance) const {
  const Impl& m = *impl_;
  if (m.ringAbove[vertex]) return false;
  if (m.faces.empty()) return true;
  if (m.nodes.empty()) throw std::logic_error("OpenSpaceTest::openWithin before build()");
  const glm::vec3 p = m.s.positions[vertex], n = m.normals[vertex];
  // Ray origins lie within sqrt(5) eps of p (lifted by eps, and pulled by
  // 2 eps into the faces at lopsided one-rings: vertexRayOrigins): reach
  // 3 eps beyond maxDistance.
  const float reach = maxDistance + 3.f * m.eps;
  const float R = maxDistance + m.maxRadius + 3.f * m.eps;
  const float limit = 0.5f * m.eps;
  // A face blocks when it is within the reach of some ray (its bounding
  // sphere) and a corner lies at or above the plane eps/2 over the tangent
  // plane (rays start at height eps and go up, so nothing lower meets them).
  // Searched in a tree of boxes, skipping nodes out of reach or wholly below
  // that plane (bounds in double with a margin for the faces' float tests:
  // the box's, and for small nodes their slab's), the highest first: a
  // vertex that is not open meets a blocking face soon.
  const glm::dvec3 pd(p), nd(n), an(glm::abs(nd));
  const double ln = glm::length(nd);
  auto height = [&](const Impl::Node& k) {  // an upper bound of k's corners' heights; -inf: out of reach
    const glm::dvec3 out = glm::max(glm::dvec3(k.clo) - pd, pd - glm::dvec3(k.chi));
    const double dist = glm::length(glm::max(out, glm::dvec3(0.0)));
    if (dist - double(k.maxR) > double(reach) * (1.0 + 1e-5) || dist > double(R) * (1.0 + 1e-5)) return -HUGE_VAL;
    const glm::dvec3 c = glm::dvec3(k.centre) - pd, half(k.half);
    double h = glm::dot(nd, c) + glm::dot(an, half);
    if (k.m != glm::vec3(0.f)) {
      const glm::dvec3 md(k.m);
      const double along = glm::dot(nd, md);
      h = std::min(h, glm::dot(nd, c) + std::max(along * double(k.lo), along * double(k.hi)) +
                          glm::length(nd - along * md) * double(k.rho));
    }
    return h + 1e-5 * ln * (glm::length(c) + glm::length(half));
  };
  const auto reaches = [&](double h) { return h >= double(limit); };
  if (!reaches(height(m.nodes[0]))) return true;
  return !searchHighestFirst(m.nodes, height, reaches, [&](const Impl::Node& k) {
    for (uint32_t i = k.begin; i < k.end; ++i) {
      const Impl::Face& f = m.faces[i];
      const glm::vec3 d = f.c - p;
      const float d2 = d.x * d.x + d.y * d.y + d.z * d.z;
      if (!(d2 < R * R) || std::sqrt(d2) - f.r > reach) continue;
      if (m.rises(f.face, p, n)) return true;
    }
    return false;
  });
}

OpenSpaceTest::Plan OpenSpaceTest::plan(const std::vector<uint32_t>& candidates, float maxDistance, int rays) {
  constexpr size_t kSample = 256;
  constexpr double kRaysPerProof = 8.0;
  const size_t stride = std::max<size_t>(1, candidates.size() / kSample);
  Plan p;
  auto shareOf = [&](auto&& open) {  // the share of the sample for which open(vertex) holds
    size_t yes = 0;
    p.sampled = 0;
    for (size_t k = 0; k < candidates.size(); k += stride, ++p.sampled) yes += open(candidates[k]);
    return p.sampled ? double(yes) / double(p.sampled) : 0.0;
  };
  p.share = shareOf([this](uint32_t v) { return !impl_->ringAbove[v]; });
  p.ownFacesOnly = p.share * double(rays) < kRaysPerProof;
  if (p.ownFacesOnly) return p;
  build();
  p.share = shareOf([&](uint32_t v) { return openWithin(v, maxDistance); });
  p.pays = p.share * double(rays) >= kRaysPerProof;
  return p;
}

std::string OpenSpaceTest::Plan::whyNot(int rays) const {
  return "the proof that vertices are open within max_distance was not run: " +
         std::string(ownFacesOnly ? "at most " : "") + std::to_string(int(std::lround(100.0 * share))) +
         "% of a sample of " + std::to_string(sampled) + " open, at " + std::to_string(rays) +
         " rays each, would save less than the proof costs";
}

struct SceneBelowTest::Impl {
  struct Node {
    glm::vec3 centre, half;  // box of the node's points
    uint32_t begin, end;     // its points in pts
    int32_t left = -1, right = -1;  // children (right = left + 1); -1: a leaf
  };
  static constexpr uint32_t kLeaf = 8;
  std::vector<glm::vec3> pts;
  std::vector<Node> nodes;
  std::vector<glm::dvec3> extremes;  // the farthest point in each of 26 directions
  std::vector<uint8_t> cornerAbove;  // per vertex: a corner of one of its faces lies above its plane
  const Scene* s = nullptr;
  const std::vector<glm::vec3>* normals = nullptr;
  float eps;

  // Fills nodes[id] over pts[b, e), split at the median of its box's longest side.
  void build(size_t id, uint32_t b, uint32_t e) {
    glm::vec3 lo(HUGE_VALF), hi(-HUGE_VALF);
    for (uint32_t i = b; i < e; ++i) { lo = glm::min(lo, pts[i]); hi = glm::max(hi, pts[i]); }
    nodes[id] = {0.5f * (lo + hi), 0.5f * (hi - lo), b, e, -1, -1};
    if (e - b <= kLeaf) return;
    const int axis = longestAxis(hi - lo);
    const uint32_t mid = b + (e - b) / 2;
    std::nth_element(pts.begin() + b, pts.begin() + mid, pts.begin() + e,
                     [axis](const glm::vec3& u, const glm::vec3& v) { return u[axis] < v[axis]; });
    const size_t left = nodes.size();
    nodes[id].left = int32_t(left);
    nodes[id].right = int32_t(left + 1);
    nodes.resize(left + 2);
    build(left, b, mid);
    build(left + 1, mid, e);
  }
};

SceneBelowTest::SceneBelowTest(const Scene& s, float eps, const std::vector<glm::vec3>& normals,
                               const std::vector<uint8_t>* usable)
    : impl_(std::make_unique<Impl>()) {
  std::vector<uint8_t> own;
  const std::vector<uint8_t>& ok = usableFaces(s, usable, own);
  Impl& m = *impl_;
  m.eps = eps;
  m.s = &s;
  m.normals = &normals;
  const double limit = 0.5 * double(eps);
  std::vector<uint8_t> used(s.vertexCount(), 0);
  m.cornerAbove.assign(s.vertexCount(), 0);
  for (size_t f = 0; f < ok.size(); ++f) {
    if (!ok[f]) continue;
    const auto& t = s.triangles[f];
    for (int k = 0; k < 3; ++k) {
      const uint32_t i = t[k];
      used[i] = 1;
      const glm::dvec3 n(normals[i]), p(s.positions[i]);
      for (int j = 1; j < 3; ++j)
        if (glm::dot(n, glm::dvec3(s.positions[t[(k + j) % 3]]) - p) > limit) m.cornerAbove[i] = 1;
    }
  }
  for (size_t v = 0; v < used.size(); ++v)
    if (used[v]) m.pts.push_back(s.positions[v]);
  if (!m.pts.empty()) {
    m.nodes.reserve(2 * (m.pts.size() / (Impl::kLeaf / 2) + 1));
    m.nodes.resize(1);
    m.build(0, 0, uint32_t(m.pts.size()));
    for (int x = -1; x <= 1; ++x)
      for (int y = -1; y <= 1; ++y)
        for (int z = -1; z <= 1; ++z) {
          if (!(x || y || z)) continue;
          const glm::dvec3 d(x, y, z);
          const auto far = std::max_element(m.pts.begin(), m.pts.end(), [&d](const glm::vec3& u, const glm::vec3& v) {
            return glm::dot(d, glm::dvec3(u)) < glm::dot(d, glm::dvec3(v));
          });
          m.extremes.push_back(glm::dvec3(*far));
        }
  }
}

SceneBelowTest::~SceneBelowTest() = default;

bool SceneBelowTest::sceneBelow(uint32_t v) const {
  const Impl& m = *impl_;
  if (m.cornerAbove[v]) return false;  // its own faces rise above its plane
  if (m.nodes.empty()) return true;
  const glm::vec3& p = m.s->positions[v];
  const glm::vec3& n = (*m.normals)[v];
  // Heights over the tangent plane in double: float rounding stays far below eps / 2.
  const glm::dvec3 nd(n), pd(p), an(glm::abs(nd));
  const double limit = 0.5 * double(m.eps);
  auto bound = [&](const Impl::Node& k) {
    return glm::dot(nd, glm::dvec3(k.centre) - pd) + glm::dot(an, glm::dvec3(k.half)) * (1.0 + 1e-6);
  };
  // Most vertices that are not open have one of the scene's extreme points
  // above their plane: no search for them.
  for (const glm::dvec3& q : m.extremes)
    if (glm::dot(nd, q - pd) > limit) return false;
  if (bound(m.nodes[0]) <= limit) return true;
  const auto reaches = [limit](double h) { return h > limit; };
  return !searchHighestFirst(m.nodes, bound, reaches, [&](const Impl::Node& k) {
    for (uint32_t i = k.begin; i < k.end; ++i)
      if (glm::dot(nd, glm::dvec3(m.pts[i]) - pd) > limit) return true;
    return false;
  });
}

}  // namespace gi

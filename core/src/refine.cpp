#include "gi/refine.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <stdexcept>
#include <string>
#include <unordered_map>
#include <unordered_set>

#include "gi/color.h"
#include "gi/emitters.h"
#include "gi/run.h"
#include "gi/sampling.h"

namespace gi {

namespace {

using EdgeKey = uint64_t;
EdgeKey edgeKey(uint32_t a, uint32_t b) {
  if (a > b) std::swap(a, b);
  return (uint64_t(a) << 32) | b;
}

constexpr int32_t kNotGreen = -1;

struct Face {
  glm::uvec3 v;
  uint32_t src;
  uint8_t depth;
  int32_t green;  // index of the green parent this face is half of, or kNotGreen
};

struct Tri {  // a triangle to red-split
  glm::uvec3 v;
  uint32_t src;
  uint8_t depth;
};

}  // namespace

struct MeshRefiner::Impl {
  Scene base;  // the input (attributes by source face)
  std::vector<Face> faces;
  std::vector<glm::vec3> positions, normals;
  std::vector<glm::uvec2> parents;
  std::vector<Tri> greenParents;                 // by green id
  std::unordered_map<EdgeKey, uint32_t> midpoint;  // edge -> its midpoint vertex
  // Vertices at one position, named by the first of them (canon): edges
  // are split by position, so that a two-sided surface whose sides have
  // vertices of their own (a triangle soup), or sheets meeting along an
  // edge with vertices in common places, are split together and stay
  // reversed copies and crack-free. Refined side by side, a partition's two
  // sides became coplanar faces of different cuts, rays met whichever the
  // caster tested first, and a sealed room lost 11% of its light (an outside
  // audit). Each side keeps its own midpoints (their normals differ).
  std::vector<uint32_t> canon;
  std::unordered_map<EdgeKey, uint32_t> canonMidpoint;  // edge by position -> its first midpoint vertex
  EdgeKey key(uint32_t a, uint32_t b) const { return edgeKey(canon[a], canon[b]); }
  std::vector<uint8_t> srcValid;  // per input face: indices in range (others are never split)
  RefinedMesh mesh;

  // The closure: which current faces are red-split, which green pairs are
  // undone (their parents red-split), and which edges end up split.
  struct Plan {
    std::vector<uint8_t> red, removed;
    std::vector<Tri> redParents;  // parents of undone green pairs
    std::unordered_set<EdgeKey> split;
  };

  Plan plan(const std::vector<uint32_t>& marked) const {
    const size_t n = faces.size();
    Plan p;
    p.red.assign(n, 0);
    p.removed.assign(n, 0);
    std::unordered_map<EdgeKey, std::vector<uint32_t>> edgeFaces;
    edgeFaces.reserve(n * 2);
    std::unordered_map<int32_t, std::vector<uint32_t>> greenChildren;
    // Faces never split (indices out of range, left out) take no part: their
    // indices may not name vertices, and an edge of theirs split elsewhere
    // would hang on them for ever.
    for (uint32_t f = 0; f < n; ++f) {
      if (!srcValid[faces[f].src]) continue;
      for (int k = 0; k < 3; ++k) edgeFaces[key(faces[f].v[k], faces[f].v[(k + 1) % 3])].push_back(f);
      if (faces[f].green != kNotGreen) greenChildren[faces[f].green].push_back(f);
    }
    std::vector<uint32_t> work;
    auto splitEdge = [&](uint32_t a, uint32_t b) {
      if (!p.split.insert(key(a, b)).second) return;
      const auto it = edgeFaces.find(key(a, b));
      if (it != edgeFaces.end()) work.insert(work.end(), it->second.begin(), it->second.end());
    };
    auto splitAll = [&](const glm::uvec3& v) {
      for (int k = 0; k < 3; ++k) splitEdge(v[k], v[(k + 1) % 3]);
    };
    auto valid = [&](uint32_t f) { return srcValid[faces[f].src] != 0; };
    auto mark = [&](uint32_t f) {
      if (p.red[f] || p.removed[f] || !valid(f)) return;
      if (faces[f].green == kNotGreen) {
        p.red[f] = 1;
        splitAll(faces[f].v);
        return;
      }
      // A green half is never split again: undo the pair, red-split the parent.
      for (uint32_t c : greenChildren.at(faces[f].green)) p.removed[c] = 1;
      const Tri& parent = greenParents[size_t(faces[f].green)];
      p.redParents.push_back(parent);
      splitAll(parent.v);
    };
    // Edges that already have a midpoint but are still edges of a face: left
    // hanging when an undone green parent was red-split next to finer faces.
    for (uint32_t f = 0; f < n; ++f)
      for (int k = 0; k < 3 && srcValid[faces[f].src]; ++k) {
        const uint32_t a = faces[f].v[k], b = faces[f].v[(k + 1) % 3];
        if (canonMidpoint.count(key(a, b))) splitEdge(a, b);
      }
    for (uint32_t f : marked)
      if (f < n) mark(f);
    while (!work.empty()) {
      const uint32_t f = work.back();
      work.pop_back();
      if (p.red[f] || p.removed[f]) continue;
      int count = 0;
      for (int k = 0; k < 3; ++k) count += p.split.count(key(faces[f].v[k], faces[f].v[(k + 1) % 3])) ? 1 : 0;
      if (count >= 2 || (count == 1 && faces[f].green != kNotGreen)) mark(f);
    }
    return p;
  }

  size_t countAfter(const Plan& p) const {
    size_t n = 0;
    for (size_t f = 0; f < faces.size(); ++f) {
      if (p.removed[f]) continue;
      if (p.red[f]) { n += 4; continue; }
      if (!srcValid[faces[f].src]) { n += 1; continue; }  // never split (apply keeps it whole)
      int count = 0;
      for (int k = 0; k < 3; ++k) count += p.split.count(key(faces[f].v[k], faces[f].v[(k + 1) % 3])) ? 1 : 0;
      n += count == 1 ? 2 : 1;
    }
    return n + 4 * p.redParents.size();
  }

  uint32_t mid(uint32_t a, uint32_t b) {
    const auto [it, added] = midpoint.try_emplace(edgeKey(a, b), uint32_t(positions.size()));
    if (added) {
      // A coincident edge's midpoint lies at the same place (the same sum of
      // the same floats): it takes that one's name.
      const auto [c, first] = canonMidpoint.try_emplace(key(a, b), uint32_t(positions.size()));
      canon.push_back(first ? uint32_t(positions.size()) : canon[c->second]);
      positions.push_back(0.5f * (positions[a] + positions[b]));
      if (!normals.empty()) {
        const glm::vec3 m = normals[a] + normals[b];
        const float l = glm::length(m);
        normals.push_back(l > 1e-20f ? m / l : normals[a]);
      }
      parents.push_back(glm::uvec2(std::min(a, b), std::max(a, b)));
    }
    return it->second;
  }

  void apply(const Plan& p) {
    std::vector<Face> out;
    out.reserve(countAfter(p));
    auto red = [&](const glm::uvec3& v, uint32_t src, uint8_t depth) {
      const uint32_t a = v.x, b = v.y, c = v.z, ab = mid(a, b), bc = mid(b, c), ca = mid(c, a);
      const uint8_t d = uint8_t(std::min(254, depth + 1));
      out.push_back({{a, ab, ca}, src, d, kNotGreen});
      out.push_back({{ab, b, bc}, src, d, kNotGreen});
      out.push_back({{ca, bc, c}, src, d, kNotGreen});
      out.push_back({{ab, bc, ca}, src, d, kNotGreen});
    };
    // Faces in order (deterministic vertex numbering), undone parents last.
    for (size_t f = 0; f < faces.size(); ++f) {
      const Face& F = faces[f];
      if (p.removed[f]) continue;
      if (p.red[f]) { red(F.v, F.src, F.depth); continue; }
      int k1 = -1, count = 0;
      for (int k = 0; k < 3 && srcValid[F.src]; ++k)
        if (p.split.count(key(F.v[k], F.v[(k + 1) % 3]))) { ++count; k1 = k; }
      if (count == 0) {
        out.push_back(F);
        continue;
      }
      // count == 1 on a red-born face: bisect it (green) from the split edge's midpoint.
      const uint32_t a = F.v[k1], b = F.v[(k1 + 1) % 3], c = F.v[(k1 + 2) % 3], m = mid(a, b);
      const int32_t id = int32_t(greenParents.size());
      greenParents.push_back({F.v, F.src, F.depth});
      out.push_back({{a, m, c}, F.src, F.depth, id});
      out.push_back({{m, b, c}, F.src, F.depth, id});
    }
    for (const Tri& t : p.redParents) red(t.v, t.src, t.depth);
    faces.swap(out);
  }

  // Red-splits `marked` and repeats the closure until no edge hangs (the
  // children of an undone green parent can border faces split in the same
  // pass: one more pass splits them in turn).
  void refineAll(const std::vector<uint32_t>& marked) {
    apply(plan(marked));
    for (int pass = 0; pass < 64; ++pass) {
      const Plan p = plan({});
      if (p.split.empty()) break;
      const size_t faceCount = faces.size(), vertexCount = positions.size();
      apply(p);
      if (faces.size() == faceCount && positions.size() == vertexCount) break;  // nothing left to split
    }
  }

  void publish() {
    RefinedMesh& m = mesh;
    m.scene.origin = base.origin;
    m.scene.unit = base.unit;
    m.scene.positions = positions;
    m.scene.vertexNormals = normals;
    const size_t n = faces.size();
    m.scene.triangles.resize(n);
    m.sourceFace.resize(n);
    m.depth.resize(n);
    for (size_t f = 0; f < n; ++f) {
      m.scene.triangles[f] = faces[f].v;
      m.sourceFace[f] = faces[f].src;
      m.depth[f] = faces[f].depth;
    }
    auto inherit = [&](auto& dst, const auto& src) {
      dst.clear();
      if (src.empty()) return;
      if (src.size() != base.faceCount()) throw std::logic_error("refinement: a per-face array changed size");
      dst.resize(n);
      for (size_t f = 0; f < n; ++f) dst[f] = src[faces[f].src];
    };
    inherit(m.scene.rho, base.rho);
    inherit(m.scene.emission, base.emission);
    inherit(m.scene.material, base.material);
    inherit(m.scene.ior, base.ior);
    inherit(m.scene.roughness, base.roughness);
    inherit(m.scene.leftOut, base.leftOut);
    m.vertexParents = parents;
    m.inputVertices = base.positions.size();
  }
};

MeshRefiner::MeshRefiner(const Scene& input) : impl_(std::make_unique<Impl>()) {
  // Per-face attributes are copied from each face's source face: every array
  // must be empty (the default) or have one entry per face.
  auto check = [&](size_t n, const char* what) {
    if (n != 0 && n != input.faceCount())
      throw std::invalid_argument(std::string("refinement: the scene's ") + what + " has " + std::to_string(n) +
                                  " entries for " + std::to_string(input.faceCount()) + " faces");
  };
  check(input.rho.size(), "reflectance");
  check(input.emission.size(), "emission");
  check(input.material.size(), "material");
  check(input.ior.size(), "index of refraction");
  check(input.roughness.size(), "roughness");
  check(input.leftOut.size(), "faces left out");
  Impl& d = *impl_;
  d.base = input;
  d.positions = input.positions;
  if (input.vertexNormals.size() == input.positions.size()) d.normals = input.vertexNormals;
  d.parents.resize(input.positions.size());
  for (uint32_t v = 0; v < input.positions.size(); ++v) d.parents[v] = glm::uvec2(v, v);
  // Each vertex named by the first vertex at its position (exact floats,
  // -0 as +0).
  d.canon.resize(input.positions.size());
  {
    struct PosHash {
      size_t operator()(const glm::vec3& p) const {
        const glm::vec3 q = p + glm::vec3(0.f);
        return std::hash<float>()(q.x) * 73856093u ^ std::hash<float>()(q.y) * 19349663u ^ std::hash<float>()(q.z) * 83492791u;
      }
    };
    std::unordered_map<glm::vec3, uint32_t, PosHash> first;
    first.reserve(input.positions.size());
    for (uint32_t v = 0; v < input.positions.size(); ++v)
      d.canon[v] = first.try_emplace(input.positions[v] + glm::vec3(0.f), v).first->second;
  }
  const size_t nv = input.positions.size();
  // A face the computation leaves out (a duplicated face's copy) is never
  // split either: it would only add patches that take no part.
  for (size_t f = 0; f < input.faceCount(); ++f) {
    const glm::uvec3& t = input.triangles[f];
    const bool leftOut = !input.leftOut.empty() && input.leftOut[f];
    d.srcValid.push_back(t.x < nv && t.y < nv && t.z < nv && !leftOut ? 1 : 0);
  }
  d.faces.resize(input.triangles.size());
  for (uint32_t f = 0; f < input.triangles.size(); ++f) d.faces[f] = {input.triangles[f], f, 0, kNotGreen};
  d.publish();
}
MeshRefiner::~MeshRefiner() = default;
MeshRefiner::MeshRefiner(MeshRefiner&&) noexcept = default;
MeshRefiner& MeshRefiner::operator=(MeshRefiner&&) noexcept = default;

const RefinedMesh& MeshRefiner::mesh() const { return impl_->mesh; }

size_t MeshRefiner::faceCountAfter(const std::vector<uint32_t>& faces) const {
  Impl trial = *impl_;
  trial.refineAll(faces);
  return trial.faces.size();
}

size_t MeshRefiner::refine(const std::vector<uint32_t>& faces) {
  const size_t before = impl_->faces.size();
  impl_->refineAll(faces);
  impl_->publish();
  return impl_->faces.size() - before;
}

namespace {

// Per vertex, the share of `rays` rays from its ray origin x (vertex normal
// n) that reach a light, -1 where none faces it: see(x, n, u) for a sample
// u of the vertex's own sequence (seeded by vertex, seed and salt) is -1
// where the light is not in front of x, else whether its ray arrives.
template <class See>
std::vector<float> visibleShare(const Scene& s, int rays, uint32_t seed, uint32_t salt, const See& see) {
  const size_t nv = s.vertexCount();
  std::vector<float> V(nv, -1.f);
  const float eps = float(sceneScale(s).rayEpsilon);
  const std::vector<glm::vec3> normals = vertexNormalsForRays(s);
  const std::vector<glm::vec3> origins = vertexRayOrigins(s, normals, eps);
  parallelBlocks(nv, Progress(nullptr), "", [&](size_t b, size_t e) {
    for (size_t i = b; i < e; ++i) {
      if (!(glm::dot(normals[i], normals[i]) > 0.5f)) continue;
      SobolOwenStream seq(hash3(uint32_t(i), seed, salt));
      int facing = 0, seen = 0;
      for (int j = 0; j < rays; ++j) {
        const int v = see(origins[i], normals[i], seq.next());
        if (v < 0) continue;
        ++facing;
        seen += v;
      }
      if (facing > 0) V[i] = float(seen) / float(facing);
    }
  });
  return V;
}

}  // namespace

std::vector<float> emitterVisibility(const Scene& s, const RayCaster& caster, int rays, uint32_t seed) {
  const EmitterSampler lights(s);
  if (lights.empty() || rays < 1) return std::vector<float>(s.vertexCount(), -1.f);
  const float eps = float(sceneScale(s).rayEpsilon);
  return visibleShare(s, rays, seed, 0x5eu, [&](const glm::vec3& x, const glm::vec3&, glm::vec2 u) {
    const EmitterSampler::Sample y = lights.sample(u);
    if (glm::dot(y.n, x - y.p) <= 0.f) return -1;  // its emitting side looks away
    const glm::vec3 d = y.p - x;
    const float dist = glm::length(d);
    if (!(dist > 2 * eps)) return 1;
    Ray r;
    r.o = x;
    r.d = d / dist;
    r.tnear = 0.f;
    r.tfar = dist * (1.f - 1e-4f) - eps;
    return caster.occluded(r) ? 0 : 1;
  });
}

std::vector<float> sunVisibility(const Scene& s, const RayCaster& caster, const SkySun& o, int rays, uint32_t seed) {
  if (!o.sun() || rays < 1) return std::vector<float>(s.vertexCount(), -1.f);
  const float sunCos = o.sunCos();
  const Frame sunFrame(o.sunDirection);
  return visibleShare(s, rays, seed, 0x5a7u, [&](const glm::vec3& x, const glm::vec3& n, glm::vec2 u) {
    Ray r;
    r.o = x;
    r.d = sunFrame.toWorld(uniformCone(u, sunCos));
    if (!(glm::dot(r.d, n) > 0.f)) return -1;  // below the tangent plane
    r.tnear = 0.f;
    r.tfar = std::numeric_limits<float>::infinity();
    return caster.occluded(r) ? 0 : 1;
  });
}

RefineMarks markForRefinement(const Scene& s, const std::vector<glm::vec3>& B, const std::vector<glm::vec3>& Bvertex,
                              const std::vector<std::vector<float>>& visibility, const std::vector<uint8_t>& depth,
                              const RefineOptions& opt) {
  const size_t n = s.faceCount();
  const auto ok = usableFaceMask(s);
  std::vector<double> A(n, 0.0), R(n, 0.0);
  std::vector<glm::vec3> normal(n, glm::vec3(0.f));
  double sumA = 0, sumAR = 0;
  for (size_t f = 0; f < n; ++f) {
    if (!ok[f]) continue;
    A[f] = faceArea(s, f);
    R[f] = std::max(0.0, double(luminance(B[f] - s.faceEmission(f))));
    normal[f] = glm::normalize(faceNormalUnnormalized(s, f));
    sumA += A[f];
    sumAR += A[f] * R[f];
  }
  const double floorR = sumA > 0 ? 0.01 * sumAR / sumA : 0.0;
  const float cosCrease = float(std::cos(opt.creaseDegrees * 3.14159265358979 / 180.0));
  std::vector<double> jump(n, 0.0), shadow(n, 0.0);
  // Edges shared by two usable faces (the first two found; non-manifold extras ignored).
  std::unordered_map<EdgeKey, uint32_t> firstFace;
  firstFace.reserve(n * 2);
  for (uint32_t f = 0; f < n; ++f) {
    if (!ok[f]) continue;
    for (int k = 0; k < 3; ++k) {
      const EdgeKey e = edgeKey(s.triangles[f][k], s.triangles[f][(k + 1) % 3]);
      const auto [it, added] = firstFace.try_emplace(e, f);
      if (added) continue;
      const uint32_t g = it->second;
      if (glm::dot(normal[f], normal[g]) < cosCrease) continue;
      const double j = std::fabs(R[f] - R[g]) / std::max({R[f], R[g], floorR, 1e-30});
      jump[f] = std::max(jump[f], j);
      jump[g] = std::max(jump[g], j);
    }
  }
  if (Bvertex.size() == s.vertexCount()) {
    // The patch's mean against the mean of the linear interpolation of its
    // corners' values (what is displayed): the interpolation error.
    for (size_t f = 0; f < n; ++f) {
      if (!ok[f]) continue;
      const glm::vec3 E = s.faceEmission(f);
      double corners = 0;
      for (int k = 0; k < 3; ++k) corners += std::max(0.0, double(luminance(Bvertex[s.triangles[f][k]] - E))) / 3.0;
      jump[f] = std::max(jump[f], std::fabs(R[f] - corners) / std::max({R[f], corners, floorR, 1e-30}));
    }
  }
  // Each light apart: one vertex seeing the emitters and another the sun
  // is no shadow boundary.
  for (const std::vector<float>& light : visibility) {
    if (light.size() != s.vertexCount()) continue;
    for (size_t f = 0; f < n; ++f) {
      if (!ok[f]) continue;
      float lo = 2.f, hi = -2.f;
      for (int k = 0; k < 3; ++k) {
        const float v = light[s.triangles[f][k]];
        if (v < 0.f) continue;
        lo = std::min(lo, v);
        hi = std::max(hi, v);
      }
      if (hi >= lo) shadow[f] = std::max(shadow[f], double(hi - lo));
    }
  }
  RefineMarks m;
  std::vector<double> priority(n, 0.0);
  for (uint32_t f = 0; f < n; ++f) {
    if (!ok[f] || (f < depth.size() && depth[f] >= opt.maxDepth)) continue;
    const bool byJump = jump[f] > opt.threshold, byShadow = shadow[f] > opt.shadowThreshold;
    if (!byJump && !byShadow) continue;
    m.byJump += byJump ? 1 : 0;
    m.byShadow += byShadow ? 1 : 0;
    priority[f] = A[f] * std::max(jump[f] / opt.threshold, shadow[f] / std::max(opt.shadowThreshold, 1e-6));
    m.faces.push_back(f);
  }
  std::stable_sort(m.faces.begin(), m.faces.end(), [&](uint32_t a, uint32_t b) { return priority[a] > priority[b]; });
  return m;
}

MeshAttributes refineAttributes(const MeshAttributes& a, const RefinedMesh& m) {
  MeshAttributes o;
  auto byFace = [&](auto& dst, const auto& src) {
    if (src.empty()) return;
    dst.resize(m.sourceFace.size());
    for (size_t f = 0; f < m.sourceFace.size(); ++f) dst[f] = src[m.sourceFace[f]];
  };
  byFace(o.faceColor, a.faceColor);
  byFace(o.faceQuality, a.faceQuality);
  byFace(o.faceSelected, a.faceSelected);
  if (!a.vertexSelected.empty()) {  // a midpoint is selected where both ends are
    o.vertexSelected.resize(m.vertexParents.size());
    for (size_t v = 0; v < m.vertexParents.size(); ++v)
      o.vertexSelected[v] = v < m.inputVertices ? a.vertexSelected[v]
                                                : uint8_t(o.vertexSelected[m.vertexParents[v].x] &&
                                                          o.vertexSelected[m.vertexParents[v].y]);
  }
  if (!a.vertexColor.empty()) {
    // Parents come before their midpoints: one pass in vertex order.
    std::vector<glm::vec3> lin(m.vertexParents.size());
    o.vertexColor.resize(m.vertexParents.size());
    for (size_t v = 0; v < m.vertexParents.size(); ++v) {
      if (v < m.inputVertices) {
        const glm::u8vec3 c = a.vertexColor[v];
        lin[v] = srgb8ToLinear(c.r, c.g, c.b);
        o.vertexColor[v] = c;
        continue;
      }
      lin[v] = 0.5f * (lin[m.vertexParents[v].x] + lin[m.vertexParents[v].y]);
      const Rgb8 c = displayMap(lin[v], 1.f);
      o.vertexColor[v] = glm::u8vec3(c.r, c.g, c.b);
    }
  }
  return o;
}

std::vector<glm::vec3> refineVertexNormals(const std::vector<glm::vec3>& n, const RefinedMesh& m) {
  if (n.empty()) return {};
  std::vector<glm::vec3> o(m.vertexParents.size());
  for (size_t v = 0; v < m.vertexParents.size(); ++v) {  // parents come before their midpoints
    if (v < m.inputVertices) {
      o[v] = n[v];
      continue;
    }
    const glm::vec3 sum = o[m.vertexParents[v].x] + o[m.vertexParents[v].y];
    const float l = glm::length(sum);
    o[v] = l > 0.f ? sum / l : o[m.vertexParents[v].x];
  }
  return o;
}

}  // namespace gi

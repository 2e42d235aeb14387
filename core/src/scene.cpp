#include "gi/scene.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <limits>
#include <stdexcept>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "gi/color.h"
#include "gi/params.h"
#include "gi/raycaster.h"

namespace gi {

bool Scene::hasEmitters() const {
  for (const auto& e : emission)
    if (e.r > 0.f || e.g > 0.f || e.b > 0.f) return true;
  return false;
}

double Scene::unitFor(double diagonal) {
  if (!(diagonal > 0.0) || !std::isfinite(diagonal)) return 1.0;
  if (diagonal >= std::ldexp(1.0, -10) && diagonal <= std::ldexp(1.0, 20)) return 1.0;
  return std::ldexp(1.0, std::ilogb(diagonal));
}

namespace {
// The vertices some triangle uses (its three indices in range): the scene's
// size, its local frame and its ray offsets follow them, so that a vertex no
// face uses, far away, moves none of them (one at 1e5 from a unit scene made
// every offset 1.7 units, and every AO value 1). Empty: no triangle uses any.
std::vector<uint8_t> referenced(size_t nv, const std::vector<glm::uvec3>& tris, size_t offset = 0,
                                std::vector<uint8_t> mask = {}) {
  for (const auto& t : tris) {
    if (t.x >= nv || t.y >= nv || t.z >= nv) continue;
    if (mask.empty()) mask.assign(offset + nv, 0);
    mask[offset + t.x] = mask[offset + t.y] = mask[offset + t.z] = 1;
  }
  return mask;
}
// Bounding box of the finite points (those the mask keeps, if any of them is
// finite, else all), in double; {lo > hi} if there are none.
std::pair<glm::dvec3, glm::dvec3> finiteBox(const std::vector<glm::dvec3>& pts, const std::vector<uint8_t>& keep = {}) {
  glm::dvec3 lo(HUGE_VAL), hi(-HUGE_VAL);
  for (size_t i = 0; i < pts.size(); ++i) {
    const glm::dvec3& p = pts[i];
    if ((keep.empty() || keep[i]) && std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z)) {
      lo = glm::min(lo, p);
      hi = glm::max(hi, p);
    }
  }
  if (!(lo.x <= hi.x) && !keep.empty()) return finiteBox(pts);
  return {lo, hi};
}
// The diagonal hi - lo, without overflow for coordinates near the double range.
double diagonalOf(const glm::dvec3& lo, const glm::dvec3& hi) {
  if (!(lo.x <= hi.x)) return 0.0;
  const glm::dvec3 half = hi * 0.5 - lo * 0.5;
  return 2.0 * glm::length(half);
}
}  // namespace

Scene Scene::fromAbsolute(const std::vector<glm::dvec3>& pts, std::vector<glm::uvec3> tris) {
  Scene s;
  auto frame = [&s](const std::pair<glm::dvec3, glm::dvec3>& box) {
    const auto& [lo, hi] = box;
    s.origin = lo.x <= hi.x ? lo * 0.5 + hi * 0.5 : glm::dvec3(0.0);
    s.unit = unitFor(diagonalOf(lo, hi));
  };
  frame(finiteBox(pts, referenced(pts.size(), tris)));
  // A vertex no face uses so far from the others that its offset overflows
  // float: the frame of all the vertices instead (as before the used ones
  // set it), so that no finite vertex becomes infinite.
  for (const auto& p : pts) {
    const glm::dvec3 d = glm::abs((p - s.origin) / s.unit);
    if (std::isfinite(p.x + p.y + p.z) && !(std::max({d.x, d.y, d.z}) <= double(std::numeric_limits<float>::max()))) {
      frame(finiteBox(pts));
      break;
    }
  }
  s.positions.reserve(pts.size());
  for (const auto& p : pts) s.positions.push_back(glm::vec3((p - s.origin) / s.unit));
  s.triangles = std::move(tris);
  return s;
}

size_t Scene::append(const Scene& o) {
  if (positions.empty() && triangles.empty()) {  // nothing here yet: take the other's frame as it is
    origin = o.origin;
    unit = o.unit;
  }
  const size_t vOff = positions.size(), fOff = triangles.size();
  auto fillTo = [](auto& v, size_t n, auto value) { if (v.size() < n) v.resize(n, value); };
  // Per-face arrays become explicit as soon as one part has them.
  const bool anyRho = !rho.empty() || !o.rho.empty(), anyE = !emission.empty() || !o.emission.empty();
  const bool anyMat = !material.empty() || !o.material.empty(), anyIor = !ior.empty() || !o.ior.empty();
  const bool anyRough = !roughness.empty() || !o.roughness.empty();
  const bool anyLeftOut = !leftOut.empty() || !o.leftOut.empty();
  const bool anyN = !vertexNormals.empty() || !o.vertexNormals.empty();
  if (anyRho) fillTo(rho, fOff, glm::vec3(0.5f));
  if (anyE) fillTo(emission, fOff, glm::vec3(0.f));
  if (anyMat) fillTo(material, fOff, Material::Diffuse);
  if (anyIor) fillTo(ior, fOff, 1.5f);
  if (anyRough) fillTo(roughness, fOff, 0.2f);
  if (anyLeftOut) fillTo(leftOut, fOff, uint8_t(0));
  if (anyN) fillTo(vertexNormals, vOff, glm::vec3(0.f));
  // The union's unit: rescale what is here (by a power of two: exact) if it changes.
  std::vector<glm::dvec3> world;
  world.reserve(positions.size() + o.positions.size());
  for (const auto& p : positions) world.push_back(toWorld(p));
  for (const auto& p : o.positions) world.push_back(o.toWorld(p));
  std::vector<uint8_t> used = referenced(positions.size(), triangles);
  if (!used.empty()) used.resize(world.size(), 0);
  used = referenced(o.positions.size(), o.triangles, positions.size(), std::move(used));
  const auto [lo, hi] = finiteBox(world, used);
  const double newUnit = unitFor(diagonalOf(lo, hi));
  if (newUnit != unit) {
    const double k = unit / newUnit;
    for (auto& p : positions) p = glm::vec3(glm::dvec3(p) * k);
    unit = newUnit;
  }
  const glm::dvec3 shift = (o.origin - origin) / unit;
  const double k = o.unit / unit;
  for (const auto& p : o.positions) positions.push_back(glm::vec3(glm::dvec3(p) * k + shift));
  for (const auto& t : o.triangles) triangles.push_back(t + glm::uvec3(uint32_t(vOff)));
  for (size_t f = 0; f < o.faceCount(); ++f) {
    if (anyRho) rho.push_back(o.faceRho(f));
    if (anyE) emission.push_back(o.faceEmission(f));
    if (anyMat) material.push_back(o.faceMaterial(f));
    if (anyIor) ior.push_back(o.ior.empty() ? 1.5f : o.ior[f]);
    if (anyRough) roughness.push_back(o.faceRoughness(f));
    if (anyLeftOut) leftOut.push_back(o.leftOut.empty() ? 0 : o.leftOut[f]);
  }
  if (anyN) {
    if (o.vertexNormals.empty()) vertexNormals.resize(positions.size(), glm::vec3(0.f));
    else vertexNormals.insert(vertexNormals.end(), o.vertexNormals.begin(), o.vertexNormals.end());
  }
  return vOff;
}

uint64_t sceneHash(const Scene& s) {
  uint64_t h = 1469598103934665603ull;
  auto mix = [&h](const void* p, size_t n) {
    const auto* b = static_cast<const unsigned char*>(p);
    for (size_t i = 0; i < n; ++i) { h ^= b[i]; h *= 1099511628211ull; }
  };
  for (const auto& p : s.positions) { const glm::dvec3 w = s.toWorld(p); mix(&w, sizeof w); }
  mix(s.triangles.data(), s.triangles.size() * sizeof(glm::uvec3));
  for (size_t f = 0; f < s.faceCount(); ++f) {
    const glm::vec3 r = s.faceRho(f), e = s.faceEmission(f);
    const auto m = uint8_t(s.faceMaterial(f));
    mix(&r, sizeof r); mix(&e, sizeof e); mix(&m, 1);
    if (s.faceMaterial(f) == Material::Glass) { const float n = s.ior.empty() ? 1.5f : s.ior[f]; mix(&n, sizeof n); }
    if (s.faceMaterial(f) == Material::Glossy) { const float a = s.faceRoughness(f); mix(&a, sizeof a); }
  }
  return h;
}

glm::vec3 faceNormalUnnormalized(const Scene& s, size_t f) {
  const auto& t = s.triangles[f];
  // Double precision: slivers of large meshes lose their normal in float.
  glm::dvec3 a(s.positions[t.x]), b(s.positions[t.y]), c(s.positions[t.z]);
  return glm::vec3(glm::cross(b - a, c - a));
}

std::vector<glm::vec3> unitFaceNormals(const Scene& s) {
  std::vector<glm::vec3> n(s.faceCount());
  for (size_t f = 0; f < s.faceCount(); ++f) {
    const glm::vec3 m = faceNormalUnnormalized(s, f);
    const float l = glm::length(m);
    n[f] = l > 0.f ? m / l : glm::vec3(0.f, 0.f, 1.f);
  }
  return n;
}

double faceArea(const Scene& s, size_t f) {
  const auto& t = s.triangles[f];
  glm::dvec3 a(s.positions[t.x]), b(s.positions[t.y]), c(s.positions[t.z]);
  return 0.5 * glm::length(glm::cross(b - a, c - a));
}


void checkSceneArrays(const Scene& s) {
  const size_t nf = s.faceCount();
  auto one = [nf](const char* name, size_t n) {
    if (n != 0 && n != nf)
      throw std::invalid_argument(std::string("Scene::") + name + " has " + std::to_string(n) + " entries for " +
                                  std::to_string(nf) + " faces: give one per face, or none");
  };
  one("rho", s.rho.size());
  one("emission", s.emission.size());
  one("material", s.material.size());
  one("ior", s.ior.size());
  one("roughness", s.roughness.size());
  one("leftOut", s.leftOut.size());
}

void checkCasterFor(const Scene& s, const RayCaster& caster) {
  const size_t n = caster.sceneFaces();
  if (n != RayCaster::kUnknownFaces && n != s.faceCount())
    throw std::invalid_argument("the ray caster was built for a scene of " + std::to_string(n) + " faces, not this one of " +
                                std::to_string(s.faceCount()) + ": build it from the scene it is used with");
}

std::vector<uint8_t> usableFaceMask(const Scene& s) {
  checkSceneArrays(s);
  const size_t nv = s.positions.size();
  std::vector<uint8_t> ok(s.faceCount(), 0);
  tbb::parallel_for(tbb::blocked_range<size_t>(0, s.faceCount(), 1 << 14), [&](const tbb::blocked_range<size_t>& r) {
    for (size_t f = r.begin(); f < r.end(); ++f) {
      const auto& t = s.triangles[f];
      if (!s.leftOut.empty() && s.leftOut[f]) continue;
      if (t.x >= nv || t.y >= nv || t.z >= nv || t.x == t.y || t.y == t.z || t.x == t.z) continue;
      if (!finite3(s.positions[t.x]) || !finite3(s.positions[t.y]) || !finite3(s.positions[t.z])) continue;
      glm::dvec3 a(s.positions[t.x]), b(s.positions[t.y]), c(s.positions[t.z]);
      double l2 = std::max({glm::dot(b - a, b - a), glm::dot(c - b, c - b), glm::dot(a - c, a - c)});
      double area2 = glm::length(glm::cross(b - a, c - a));
      // Degenerate: zero area, or height below float resolution of its longest edge.
      if (!(area2 > 1e-12 * l2) || l2 == 0.0) continue;
      // Or too small for its normal in float (edges of 1e-12: the cross
      // product's square underflows, and a ray from it had no direction).
      const glm::vec3 m = faceNormalUnnormalized(s, f);
      if (!(glm::dot(m, m) >= std::numeric_limits<float>::min())) continue;
      ok[f] = 1;
    }
  });
  return ok;
}

const std::vector<uint8_t>& usableFaces(const Scene& s, const std::vector<uint8_t>* known, std::vector<uint8_t>& own) {
  if (known) return *known;
  own = usableFaceMask(s);
  return own;
}

namespace {
// acc[t[k]] += term k of face f (c(f, terms) fills the face's three) for
// every usable face f in ascending order, skipping unused terms;
// count[t[k]] counts the terms added and length[t[k]] sums their lengths. The terms are computed in parallel, a block of faces at a
// time, and added in face order: the bits of the sequential loop, for any
// number of threads (a mesh's normals at 3.8M faces: 0.57 -> 0.25 s on 2
// cores).
struct CornerTerm {
  glm::dvec3 v{0.0};
  bool used = false;
};
template <class Term>
void addCornerTerms(const Scene& s, const std::vector<uint8_t>& ok, std::vector<glm::dvec3>& acc,
                    std::vector<int>* count, Term&& c, std::vector<double>* length = nullptr) {
  constexpr size_t kBlock = size_t(1) << 16;
  std::vector<CornerTerm> terms(3 * std::min(kBlock, s.faceCount()));
  for (size_t b = 0; b < s.faceCount(); b += kBlock) {
    const size_t e = std::min(s.faceCount(), b + kBlock);
    tbb::parallel_for(tbb::blocked_range<size_t>(b, e, 1024), [&](const tbb::blocked_range<size_t>& r) {
      for (size_t f = r.begin(); f < r.end(); ++f)
        if (ok[f]) c(f, &terms[3 * (f - b)]);
        else terms[3 * (f - b)] = terms[3 * (f - b) + 1] = terms[3 * (f - b) + 2] = CornerTerm{};
    });
    for (size_t f = b; f < e; ++f)
      for (int k = 0; k < 3; ++k) {
        const CornerTerm& t = terms[3 * (f - b) + k];
        if (!t.used) continue;
        acc[s.triangles[f][k]] += t.v;
        if (count) ++(*count)[s.triangles[f][k]];
        if (length) (*length)[s.triangles[f][k]] += glm::length(t.v);
      }
  }
}
}  // namespace

std::vector<glm::vec3> computeVertexNormals(const Scene& s, const std::vector<uint8_t>* usable) {
  std::vector<glm::dvec3> acc(s.positions.size(), glm::dvec3(0.0));
  std::vector<double> angles(s.positions.size(), 0.0);
  std::vector<uint8_t> own;
  addCornerTerms(s, usableFaces(s, usable, own), acc, nullptr, [&s](size_t f, CornerTerm* out) {
    const auto& t = s.triangles[f];
    const glm::dvec3 p[3] = {glm::dvec3(s.positions[t.x]), glm::dvec3(s.positions[t.y]), glm::dvec3(s.positions[t.z])};
    const glm::dvec3 n = glm::normalize(glm::cross(p[1] - p[0], p[2] - p[0]));
    for (int k = 0; k < 3; ++k) {
      // Angle-weighted (Thürmer and Wüthrich 1998): independent of tessellation.
      glm::dvec3 e1 = glm::normalize(p[(k + 1) % 3] - p[k]), e2 = glm::normalize(p[(k + 2) % 3] - p[k]);
      double angle = std::acos(std::clamp(glm::dot(e1, e2), -1.0, 1.0));
      out[k] = {angle * n, true};
    }
  }, &angles);
  std::vector<glm::vec3> n(acc.size());
  tbb::parallel_for(tbb::blocked_range<size_t>(0, acc.size(), 1 << 14), [&](const tbb::blocked_range<size_t>& r) {
    for (size_t i = r.begin(); i < r.end(); ++i) {
      // Terms that cancel (a two-sided surface: each face with a reversed
      // copy) leave a rounding residue, about 1e-16 of the angles summed,
      // in a random direction: no normal. A sharply folded vertex keeps
      // its normal (a needle's tip of half-angle a: its terms sum to about
      // 2 pi a^2, a times its angles' 2 pi a).
      double l = glm::length(acc[i]);
      n[i] = l > 1e-12 * angles[i] ? glm::vec3(acc[i] / l) : glm::vec3(0.f);
    }
  });
  return n;
}

std::vector<glm::vec3> vertexNormalsForRays(const Scene& s, const std::vector<uint8_t>* usable) {
  if (s.vertexNormals.size() != s.vertexCount()) return computeVertexNormals(s, usable);
  std::vector<uint8_t> own;
  const std::vector<uint8_t>& ok = usableFaces(s, usable, own);
  std::vector<uint8_t> onFace(s.vertexCount(), 0);
  for (size_t f = 0; f < ok.size(); ++f)
    if (ok[f])
      for (int k = 0; k < 3; ++k) onFace[s.triangles[f][k]] = 1;
  std::vector<glm::vec3> n = s.vertexNormals;
  std::vector<size_t> replaced;  // zero, NaN or Inf on a usable face: the faces' normal
  for (size_t i = 0; i < n.size(); ++i) {
    const std::optional<glm::vec3> u = onFace[i] ? unitKeepingBits(n[i]) : std::nullopt;
    if (onFace[i] && !u) replaced.push_back(i);
    n[i] = u.value_or(glm::vec3(0.f));
  }
  if (!replaced.empty()) {
    const std::vector<glm::vec3> computed = computeVertexNormals(s, &ok);
    for (size_t i : replaced) n[i] = unitKeepingBits(computed[i]).value_or(glm::vec3(0.f));
  }
  return n;
}

namespace {

// What the faces' corner positions say: the faces that repeat another's
// corners in its turn, the two-sided pairs, and the edges along which two
// faces run the same way.
struct CornerGroups {
  std::vector<std::pair<uint32_t, uint32_t>> duplicates;  // (copy, original)
  size_t twoSidedPairs = 0, misorientedEdges = 0;
  size_t borderEdges = 0;  // edges (by position) of one face only
};

// ok: usable faces; used: the vertices they use.
CornerGroups cornerGroups(const Scene& s, const std::vector<uint8_t>& ok, const std::vector<uint8_t>& used) {
  const size_t nv = s.vertexCount(), nf = s.faceCount();
  CornerGroups g;
  // Corners with equal positions get one id (the vertices in position
  // order), then faces are compared as sorted id triples: integers, where
  // sorting the faces by their nine coordinates cost 0.2 s a call at a
  // million triangles.
  std::vector<uint32_t> order;
  order.reserve(nv);
  for (size_t i = 0; i < nv; ++i)
    if (used[i]) order.push_back(uint32_t(i));
  auto less = [&](uint32_t a, uint32_t b) {
    const glm::vec3 &p = s.positions[a], &q = s.positions[b];
    return p.x != q.x ? p.x < q.x : p.y != q.y ? p.y < q.y : p.z < q.z;
  };
  std::sort(order.begin(), order.end(), less);
  std::vector<uint32_t> id(nv, 0);
  for (size_t k = 0; k < order.size(); ++k)
    id[order[k]] = k > 0 && !less(order[k - 1], order[k]) ? id[order[k - 1]] : uint32_t(k);
  // The sorted ids, the turn (0 where the sorted order is a rotation of the
  // face's own, 1 where it is reversed) and the face.
  std::vector<std::array<uint32_t, 5>> keys;
  keys.reserve(nf);
  for (size_t f = 0; f < nf; ++f) {
    if (!ok[f]) continue;
    const std::array<uint32_t, 3> turn = {id[s.triangles[f].x], id[s.triangles[f].y], id[s.triangles[f].z]};
    std::array<uint32_t, 3> c = turn;
    std::sort(c.begin(), c.end());
    const int first = int(std::find(turn.begin(), turn.end(), c[0]) - turn.begin());
    keys.push_back({c[0], c[1], c[2], turn[size_t((first + 1) % 3)] == c[1] ? 0u : 1u, uint32_t(f)});
  }
  std::sort(keys.begin(), keys.end());
  // Faces on the same corners in the same turn are one face listed again: a
  // group's original is the face that emits, else one that is not diffuse
  // (a mirror or glass layer lying on a wall), else the first; the others
  // are its duplicates (a light panel given as a layer over the ceiling's
  // own faces is the light, not a copy of the ceiling: an outside review).
  // A group on the same corners with both turns is a two-sided pair.
  auto rank = [&](uint32_t f) {
    const glm::vec3 E = s.faceEmission(f);
    return (E.r > 0.f || E.g > 0.f || E.b > 0.f) ? 0 : s.faceMaterial(f) != Material::Diffuse ? 1 : 2;
  };
  for (size_t first = 0; first < keys.size();) {
    size_t end = first + 1;
    while (end < keys.size() && std::equal(keys[end].begin(), keys[end].begin() + 4, keys[first].begin())) ++end;
    if (first > 0 && std::equal(keys[first].begin(), keys[first].begin() + 3, keys[first - 1].begin())) ++g.twoSidedPairs;
    size_t best = first;
    for (size_t k = first + 1; k < end; ++k)
      if (rank(keys[k][4]) < rank(keys[best][4])) best = k;
    for (size_t k = first; k < end; ++k)
      if (k != best) g.duplicates.push_back({keys[k][4], keys[best][4]});
    first = end;
  }
  // Edges met by exactly two faces that run along them the same way: one of
  // the two is turned over (its front is the other's back). Grouped by the
  // edge's lower id (a count, then the slots: linear, no sort of all edges).
  std::vector<uint32_t> start(order.size() + 2, 0), slot;
  auto each = [&](auto&& visit) {
    for (const auto& key : keys) {
      const glm::uvec3& t = s.triangles[key[4]];
      for (int e = 0; e < 3; ++e) visit(id[t[e]], id[t[(e + 1) % 3]]);
    }
  };
  each([&](uint32_t a, uint32_t b) { ++start[std::min(a, b) + 2]; });
  for (size_t k = 2; k < start.size(); ++k) start[k] += start[k - 1];
  slot.resize(3 * keys.size());
  each([&](uint32_t a, uint32_t b) { slot[start[std::min(a, b) + 1]++] = (std::max(a, b) << 1) | (a < b ? 0u : 1u); });
  for (size_t lo = 0; lo + 1 < start.size(); ++lo) {
    const auto first = slot.begin() + start[lo], last = slot.begin() + start[lo + 1];
    std::sort(first, last);
    for (auto it = first; it != last;) {
      auto end = it;
      while (end != last && (*end >> 1) == (*it >> 1)) ++end;
      if (end - it == 2 && *it == *(it + 1)) ++g.misorientedEdges;
      if (end - it == 1) ++g.borderEdges;
      it = end;
    }
  }
  return g;
}

}  // namespace

std::vector<std::pair<uint32_t, uint32_t>> duplicatedFaces(const Scene& s) {
  const std::vector<uint8_t> ok = usableFaceMask(s);
  std::vector<uint8_t> used(s.vertexCount(), 0);
  for (size_t f = 0; f < ok.size(); ++f)
    if (ok[f]) used[s.triangles[f].x] = used[s.triangles[f].y] = used[s.triangles[f].z] = 1;
  return cornerGroups(s, ok, used).duplicates;
}

std::vector<uint8_t> copyOnlyVertices(const Scene& s) {
  if (std::find(s.leftOut.begin(), s.leftOut.end(), uint8_t(1)) == s.leftOut.end()) return {};
  const size_t nv = s.vertexCount();
  std::vector<uint8_t> mark(nv, 0);  // 1: on a left-out face, 2: on a face kept
  for (size_t f = 0; f < s.faceCount(); ++f) {
    const glm::uvec3& t = s.triangles[f];
    if (t.x >= nv || t.y >= nv || t.z >= nv) continue;
    const uint8_t m = f < s.leftOut.size() && s.leftOut[f] ? 1 : 2;
    for (int k = 0; k < 3; ++k) mark[t[k]] = std::max(mark[t[k]], m);
  }
  for (uint8_t& m : mark) m = m == 1;
  return mark;
}

SceneReport analyzeScene(const Scene& s, bool duplicateFaces, const std::vector<uint8_t>* usable,
                         std::vector<std::pair<uint32_t, uint32_t>>* duplicates) {
  SceneReport r;
  r.vertices = s.vertexCount();
  r.faces = s.faceCount();
  const size_t nv = r.vertices;
  std::vector<uint8_t> used(nv, 0), finite(nv, 0);
  glm::dvec3 lo(HUGE_VAL), hi(-HUGE_VAL);
  for (size_t i = 0; i < nv; ++i) {
    finite[i] = finite3(s.positions[i]);
    if (!finite[i]) { ++r.nonFiniteVertices; continue; }
    lo = glm::min(lo, s.toWorld(s.positions[i]));
    hi = glm::max(hi, s.toWorld(s.positions[i]));
  }
  std::vector<uint8_t> own;
  const std::vector<uint8_t>& ok = usableFaces(s, usable, own);
  for (size_t f = 0; f < r.faces; ++f) {
    const auto& t = s.triangles[f];
    if (t.x >= nv || t.y >= nv || t.z >= nv || t.x == t.y || t.y == t.z || t.x == t.z) { ++r.invalidFaces; continue; }
    if (!finite[t.x] || !finite[t.y] || !finite[t.z]) { ++r.facesOnNonFinite; continue; }
    if (!s.leftOut.empty() && s.leftOut[f]) { ++r.leftOutFaces; continue; }
    if (!ok[f]) { ++r.degenerateFaces; continue; }
    used[t.x] = used[t.y] = used[t.z] = 1;
    glm::vec3 E = s.faceEmission(f);
    if (E.r > 0.f || E.g > 0.f || E.b > 0.f) {
      ++r.emitterFaces;
      r.emittedPower += double(luminance(E)) * faceArea(s, f) * s.unit * s.unit;
    }
  }
  const std::vector<uint8_t> copies = copyOnlyVertices(s);
  for (size_t i = 0; i < nv; ++i) r.isolatedVertices += (finite[i] && !used[i] && (copies.empty() || !copies[i])) ? 1 : 0;
  // Duplicated faces: the same three corner positions (in any order) as an
  // earlier usable face. Coplanar copies hide each other at random in ray
  // casting, so exact energy accounting does not hold for them.
  if (duplicateFaces) {
    CornerGroups g = cornerGroups(s, ok, used);
    r.duplicateFaces = g.duplicates.size();
    if (duplicates) *duplicates = std::move(g.duplicates);
    r.twoSidedPairs = g.twoSidedPairs;
    r.misorientedEdges = g.misorientedEdges;
    r.borderEdges = g.borderEdges;
  }
  if (lo.x <= hi.x) { r.bboxMin = lo; r.bboxMax = hi; }
  const SceneScale sc = sceneScale(s);
  r.diagonal = sc.diagonal * s.unit;
  r.rayEpsilon = sc.rayEpsilon;
  return r;
}

SceneScale sceneScale(const Scene& s) {
  const std::vector<uint8_t> used = referenced(s.vertexCount(), s.triangles);
  bool any = false;  // a used vertex that is finite (else all vertices count)
  for (size_t i = 0; i < used.size() && !any; ++i) any = used[i] && finite3(s.positions[i]);
  glm::dvec3 lo(HUGE_VAL), hi(-HUGE_VAL);
  double maxAbs = 0.0;
  for (size_t i = 0; i < s.vertexCount(); ++i) {
    const glm::vec3& p = s.positions[i];
    if (!finite3(p) || (any && !used[i])) continue;
    lo = glm::min(lo, glm::dvec3(p));
    hi = glm::max(hi, glm::dvec3(p));
    maxAbs = std::max({maxAbs, double(std::fabs(p.x)), double(std::fabs(p.y)), double(std::fabs(p.z))});
  }
  SceneScale sc;
  sc.lo = lo;
  sc.hi = hi;
  sc.maxAbs = maxAbs;
  if (lo.x <= hi.x) sc.diagonal = glm::length(hi - lo);
  // Ray offsets: a small fraction of the scene size, and never below the float
  // resolution of the largest local coordinate (positions are centred).
  sc.rayEpsilon = std::max(sc.diagonal * 1e-5, maxAbs * 64.0 * 1.19e-7);
  if (sc.rayEpsilon == 0.0) sc.rayEpsilon = 1e-6;
  return sc;
}

std::string SceneReport::summary() const {
  char buf[512];
  std::snprintf(buf, sizeof buf,
                "%zu vertices, %zu faces (%zu usable); skipped: %zu degenerate, %zu invalid, %zu on NaN/Inf vertices; "
                "%zu NaN/Inf vertices, %zu isolated vertices; %zu emitter faces; bbox diagonal %.6g",
                vertices, faces, usableFaces(), degenerateFaces, invalidFaces, facesOnNonFinite, nonFiniteVertices,
                isolatedVertices, emitterFaces, diagonal);
  std::string line = buf;
  if (duplicateFaces)
    line += "; " + std::to_string(duplicateFaces) +
            " duplicated faces (coplanar copies shadow each other at random: remove them for exact results)";
  if (leftOutFaces)
    line += "; " + std::to_string(leftOutFaces) + " duplicated faces left out";
  if (misorientedEdges)
    line += "; " + std::to_string(misorientedEdges) + " edges between faces turned opposite ways";
  if (twoSidedPairs)
    line += "; " + std::to_string(twoSidedPairs) +
            " two-sided pairs (faces with a reversed copy on the same corners: lit on both sides)";
  return line;
}

}  // namespace gi

namespace gi {
namespace {
constexpr double kPullFactor = 2.0;  // the pull's length in ray offsets
}  // namespace

std::vector<glm::vec3> vertexRayOrigins(const Scene& s, const std::vector<glm::vec3>& normals, float eps,
                                        const std::vector<uint8_t>* usable) {
  const size_t nv = s.vertexCount();
  // The pull: the mean direction over the wedge the vertex's faces span,
  // each face's corner adding the integral of the unit directions across
  // its angle theta, 2 sin(theta / 2) along the corner's bisector, over the
  // sum of the angles. It does not depend on how the wedge is cut into
  // triangles: the mean of the directions to the faces' centroids did (an
  // outside audit, all where a floor meets walls of its own: thin floor
  // triangles along the crease cancelled each other and left the origin on
  // the wall's plane, 0.09 for 0.33; at an L-shaped room's 270 degree
  // corner a fan's centroids pointed into the block, 0.0035 for 0.020; a
  // floor corner made of one sliver was pulled along the wall).
  std::vector<glm::dvec3> pull(nv, glm::dvec3(0.0)), angle(nv, glm::dvec3(0.0));
  std::vector<uint8_t> own;
  const std::vector<uint8_t>& ok = usableFaces(s, usable, own);
  auto corners = [&s](size_t f, CornerTerm* out, bool angleOnly) {
    const auto& t = s.triangles[f];
    const glm::dvec3 p[3] = {glm::dvec3(s.positions[t.x]), glm::dvec3(s.positions[t.y]), glm::dvec3(s.positions[t.z])};
    for (int k = 0; k < 3; ++k) {
      const glm::dvec3 a = p[(k + 1) % 3] - p[k], b = p[(k + 2) % 3] - p[k];
      const double la = glm::length(a), lb = glm::length(b);
      if (!(la > 0.0) || !(lb > 0.0)) { out[k] = CornerTerm{}; continue; }
      const glm::dvec3 ua = a / la, ub = b / lb, mid = ua + ub;
      const double theta = std::acos(std::clamp(glm::dot(ua, ub), -1.0, 1.0)), lm = glm::length(mid);
      if (angleOnly) out[k] = CornerTerm{glm::dvec3(theta, 0.0, 0.0), true};
      else out[k] = lm > 0.0 ? CornerTerm{mid / lm * (2.0 * std::sin(0.5 * theta)), true} : CornerTerm{};
    }
  };
  addCornerTerms(s, ok, pull, nullptr, [&](size_t f, CornerTerm* out) { corners(f, out, false); });
  addCornerTerms(s, ok, angle, nullptr, [&](size_t f, CornerTerm* out) { corners(f, out, true); });
  std::vector<glm::dvec3> shift(nv, glm::dvec3(0.0));
  tbb::parallel_for(tbb::blocked_range<size_t>(0, nv, 1 << 14), [&](const tbb::blocked_range<size_t>& r) {
    for (size_t i = r.begin(); i < r.end(); ++i) {
      const glm::dvec3 n(normals[i]);
      glm::dvec3 p = angle[i].x > 0.0 ? pull[i] / angle[i].x : glm::dvec3(0.0);
      p -= n * glm::dot(p, n);  // tangential part only
      const double l = glm::length(p);
      // A straight border gives 2 / pi, an L-shaped room's inner corner
      // 0.30; a full one-ring 0 (no pull). Twice eps in the plane and eps
      // along the normal: the origin lies 27 degrees above its faces, in
      // front of another sheet meeting them at a crease down to that angle
      // (at eps and eps, 45 degrees: a 30 degree crease read 0.93 for 0.07).
      if (l > 0.2) shift[i] = kPullFactor * p / l;
    }
  });
  // The pull must not take the origin behind one of the vertex's own faces:
  // at a box's inner corner whose floor is a fan of six triangles, the floor
  // faces outnumber the walls' in the pull, which tipped it down through the
  // floor, and every path from the corner started outside the box (an
  // outside audit: the reference read 0 there, radiosity and photon mapping
  // the direct light alone). Along each face's normal m the offset keeps at
  // least half the clearance the normal alone gives, on the side of the
  // face the normal leaves on (the front for outward normals, the back for
  // thickness's inward ones: an unwelded cube's corner was pulled out of
  // the cube through its own face): |n.m + a (shift.m)| >= |n.m| / 2, the
  // largest such a in [0, 1].
  std::vector<double> keep(nv, 1.0);
  for (size_t f = 0; f < ok.size(); ++f) {
    if (!ok[f]) continue;
    const glm::dvec3 m = glm::normalize(glm::dvec3(faceNormalUnnormalized(s, f)));
    for (int k = 0; k < 3; ++k) {
      const uint32_t i = s.triangles[f][k];
      const double clearance = glm::dot(glm::dvec3(normals[i]), m);
      const double along = (clearance < 0.0 ? -1.0 : 1.0) * glm::dot(shift[i], m);
      if (!(along < 0.0)) continue;
      keep[i] = std::min(keep[i], std::max(0.0, 0.5 * std::fabs(clearance) / -along));
    }
  }
  std::vector<glm::vec3> o(nv);
  tbb::parallel_for(tbb::blocked_range<size_t>(0, nv, 1 << 14), [&](const tbb::blocked_range<size_t>& r) {
    for (size_t i = r.begin(); i < r.end(); ++i)
      o[i] = glm::vec3(glm::dvec3(s.positions[i]) + double(eps) * (glm::dvec3(normals[i]) + keep[i] * shift[i]));
  });
  return o;
}

glm::dvec3 closestPointOnTriangle(const glm::dvec3& p, const glm::dvec3& a, const glm::dvec3& b, const glm::dvec3& c) {
  const glm::dvec3 ab = b - a, ac = c - a, ap = p - a;
  const double d1 = glm::dot(ab, ap), d2 = glm::dot(ac, ap);
  if (d1 <= 0 && d2 <= 0) return a;
  const glm::dvec3 bp = p - b;
  const double d3 = glm::dot(ab, bp), d4 = glm::dot(ac, bp);
  if (d3 >= 0 && d4 <= d3) return b;
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) return a + ab * (d1 / (d1 - d3));
  const glm::dvec3 cp = p - c;
  const double d5 = glm::dot(ab, cp), d6 = glm::dot(ac, cp);
  if (d6 >= 0 && d5 <= d6) return c;
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) return a + ac * (d2 / (d2 - d6));
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && d4 - d3 >= 0 && d5 - d6 >= 0) return b + (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6)));
  const double den = 1 / (va + vb + vc);
  return a + ab * (vb * den) + ac * (vc * den);
}
}  // namespace gi

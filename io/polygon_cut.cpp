// Cutting a polygon as read into triangles (internal to io/): convex faces as
// a fan, concave ones by ear clipping in their plane, faces listing a vertex
// twice in their places. Used by mesh_io.cpp's loader.
#include <algorithm>
#include <cmath>
#include <vector>

#include <glm/glm.hpp>
#include <glm/gtc/constants.hpp>

#include "mesh_parts.h"

namespace gi::io::detail {

namespace {

// The total turning of a closed polygon in the plane: the sum of the angles
// between consecutive edges (2 pi for a simple polygon, 4 pi for a
// pentagram, 0 for a figure eight).
double turning(const std::vector<glm::dvec2>& q) {
  const size_t n = q.size();
  double sum = 0.0;
  for (size_t i = 0; i < n; ++i) {
    const glm::dvec2 e = q[(i + 1) % n] - q[i], f = q[(i + 2) % n] - q[(i + 1) % n];
    sum += std::atan2(e.x * f.y - e.y * f.x, glm::dot(e, f));
  }
  return sum;
}

// Whether two edges that share no corner cross properly (each edge's ends
// strictly on either side of the other's line): O(n^2), for polygons of at
// most kMaxEarClipped corners.
bool crossesItself(const std::vector<glm::dvec2>& q) {
  const size_t n = q.size();
  auto side = [](const glm::dvec2& a, const glm::dvec2& b, const glm::dvec2& c) {
    const double t = (b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x);
    return (t > 0.0) - (t < 0.0);
  };
  for (size_t i = 0; i < n; ++i)
    for (size_t j = i + 2; j < n; ++j) {
      if (i == 0 && j == n - 1) continue;  // neighbours through the last corner
      const glm::dvec2 &a = q[i], &b = q[i + 1], &c = q[j], &d = q[(j + 1) % n];
      if (side(a, b, c) * side(a, b, d) < 0 && side(c, d, a) * side(c, d, b) < 0) return true;
    }
  return false;
}
// A polygon's triangles as corner positions k (0..n-1) of its vertex list v:
// a fan from the first corner where the polygon is convex (the same
// triangles as before for every convex face), else ear clipping in the
// plane of its Newell normal, so that a concave polygon's triangles stay
// inside it (a fan from a reflex corner covered the notch outside: a quad
// of area 1 came out 3; an outside audit). Ears are clipped in O(n^2) a
// round; a concave polygon of more than kMaxEarClipped corners, or one
// where no ear is found (self-intersecting), keeps the fan for what is
// left, and the function returns false: the loader warns (a 258-corner comb
// of area 192 came out of area 4288, a quarter of its triangles reversed,
// with no word; an outside audit).
bool triangulate(const std::vector<glm::dvec3>& pts, const uint32_t* v, size_t n, std::vector<glm::uvec3>& out) {
  out.clear();
  if (n == 3) {  // most faces: nothing to decide, nothing to allocate
    out.push_back({0, 1, 2});
    return true;
  }
  auto fan = [&](const std::vector<uint32_t>& k) {
    for (size_t i = 1; i + 1 < k.size(); ++i) out.push_back({k[0], k[i], k[i + 1]});
  };
  std::vector<uint32_t> left(n);
  for (size_t i = 0; i < n; ++i) left[i] = uint32_t(i);
  if (n <= 3) return fan(left), true;
  glm::dvec3 normal(0.0);  // Newell's normal
  for (size_t i = 0; i < n; ++i) {
    const glm::dvec3 &a = pts[v[i]], &b = pts[v[(i + 1) % n]];
    normal += glm::dvec3((a.y - b.y) * (a.z + b.z), (a.z - b.z) * (a.x + b.x), (a.x - b.x) * (a.y + b.y));
  }
  if (!(glm::length(normal) > 0.0)) {
    // No net area: either no area whatever the split (every corner on one
    // line), or lobes of opposite turn that cancel (a symmetric bow tie),
    // which crosses itself.
    for (size_t i = 1; i + 1 < n; ++i)
      if (glm::length(glm::cross(pts[v[i]] - pts[v[0]], pts[v[i + 1]] - pts[v[0]])) > 0.0) return fan(left), false;
    return fan(left), true;
  }
  // The plane's two axes, from the polygon's own first corner (2-D coordinates
  // of the same scale as the polygon).
  const glm::dvec3 nz = glm::normalize(normal);
  const glm::dvec3 ax = glm::normalize(std::fabs(nz.x) < 0.9 ? glm::cross(nz, glm::dvec3(1, 0, 0)) : glm::cross(nz, glm::dvec3(0, 1, 0)));
  const glm::dvec3 ay = glm::cross(nz, ax);
  std::vector<glm::dvec2> q(n);
  for (size_t i = 0; i < n; ++i) {
    const glm::dvec3 d = pts[v[i]] - pts[v[0]];
    q[i] = {glm::dot(d, ax), glm::dot(d, ay)};
  }
  auto turn = [&](uint32_t a, uint32_t b, uint32_t c) {  // > 0: counter-clockwise about the normal
    return (q[b].x - q[a].x) * (q[c].y - q[a].y) - (q[b].y - q[a].y) * (q[c].x - q[a].x);
  };
  bool convex = true;
  for (size_t i = 0; i < n && convex; ++i) convex = turn(uint32_t(i), uint32_t((i + 1) % n), uint32_t((i + 2) % n)) >= 0.0;
  // Turning one way at every corner, a polygon is convex when it turns once
  // round; a pentagram turns the same way at every corner and goes round
  // twice.
  if (convex) return fan(left), std::fabs(turning(q)) < 3.0 * glm::pi<double>();
  if (n > kMaxEarClipped) return fan(left), false;
  if (crossesItself(q)) return fan(left), false;  // a bow tie: ear clipping would cut it as if it did not
  auto inside = [&](uint32_t p, uint32_t a, uint32_t b, uint32_t c) {
    return turn(a, b, p) >= 0.0 && turn(b, c, p) >= 0.0 && turn(c, a, p) >= 0.0;
  };
  // Walking round the corners, clipping each ear met: a whole round without
  // one means a self-intersecting polygon.
  size_t i = 0, misses = 0;
  while (left.size() > 3 && misses < left.size()) {
    const size_t m = left.size();
    i %= m;
    const uint32_t a = left[(i + m - 1) % m], b = left[i], c = left[(i + 1) % m];
    bool ear = turn(a, b, c) > 0.0;  // reflex or flat: no ear
    for (size_t j = 0; j < m && ear; ++j) {
      const uint32_t p = left[j];
      if (p != a && p != b && p != c && q[p] != q[a] && q[p] != q[b] && q[p] != q[c]) ear = !inside(p, a, b, c);
    }
    if (!ear) {
      ++i, ++misses;
      continue;
    }
    out.push_back({a, b, c});
    left.erase(left.begin() + long(i));
    misses = 0;
  }
  fan(left);
  return left.size() <= 3;
}

}  // namespace

// A face as triangles of vertex ids, appended to `tris`; false where it was
// split as a fan that may cover area outside it. A face listing a vertex
// twice (exporters leave them: a collapsed edge's "a b b", a quad "a b b c")
// has each run of one vertex taken as one corner; what is left, with three
// corners or more and none twice, is cut as any polygon, and the triangles it
// lacks of n - 2 are added as (r, r, r) of the repeated vertex, so that every
// later face keeps its number (a polygon of n corners is n - 2 triangles, as
// MeshLab counts them). Otherwise (a triangle "a b b", a polygon through one
// vertex twice) it is a fan of its corners as listed. Triangles with a
// repeated corner have no area: every filter leaves them out (invalid faces),
// as it does MeshLab's own.
bool cutFace(const std::vector<glm::dvec3>& pts, const uint32_t* v, size_t n, std::vector<uint32_t>& once,
             std::vector<glm::uvec3>& corners, std::vector<glm::uvec3>& tris) {
  once.clear();
  uint32_t twice = kNone;
  for (size_t i = 0; i < n; ++i)
    if (v[i] != v[(i + n - 1) % n]) once.push_back(v[i]);
    else if (twice == kNone) twice = v[i];
  if (twice == kNone && n > 3) twice = repeatedIndex(std::vector<uint32_t>(v, v + n));
  if (twice == kNone) {
    const bool cut = triangulate(pts, v, n, corners);
    for (const glm::uvec3& k : corners) tris.push_back({v[k.x], v[k.y], v[k.z]});
    return cut;
  }
  if (once.size() >= 3 && repeatedIndex(once) == kNone) {
    const bool cut = triangulate(pts, once.data(), once.size(), corners);
    for (const glm::uvec3& k : corners) tris.push_back({once[k.x], once[k.y], once[k.z]});
    for (size_t k = corners.size(); k + 2 < n; ++k) tris.push_back(glm::uvec3(twice));
    return cut;
  }
  for (size_t i = 1; i + 1 < n; ++i) tris.push_back({v[0], v[i], v[i + 1]});
  return n == 3;
}

}  // namespace gi::io::detail

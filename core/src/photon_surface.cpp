// The surface area inside a gather sphere (photon_surface.h) and the exact
// area of a triangle inside a ball.
#include "photon_surface.h"

#include <algorithm>
#include <cmath>

#include "gi/photon.h"
#include "gi/specular.h"
#include "photon_internal.h"

namespace gi {

namespace {

double cross2(const glm::dvec2& a, const glm::dvec2& b) { return a.x * b.y - a.y * b.x; }

// Signed area of the disk |p| <= R intersected with the triangle (0, A, B):
// the segment AB is cut where it crosses the circle; pieces inside give
// triangles (0, P, Q), pieces outside the circular sectors between P and Q.
double edgeTerm(const glm::dvec2& A, const glm::dvec2& B, double R) {
  const glm::dvec2 d = B - A;
  const double a = glm::dot(d, d), b = glm::dot(A, d), c = glm::dot(A, A) - R * R;
  double t[4] = {0.0, 0.0, 0.0, 1.0};
  int n = 1;
  const double disc = b * b - a * c;
  if (a > 0.0 && disc > 0.0) {
    const double sq = std::sqrt(disc);
    for (double ti : {(-b - sq) / a, (-b + sq) / a})
      if (ti > 0.0 && ti < 1.0) t[n++] = ti;
  }
  t[n++] = 1.0;
  double sum = 0.0;
  for (int i = 0; i + 1 < n; ++i) {
    const glm::dvec2 P = A + t[i] * d, Q = A + t[i + 1] * d, mid = A + 0.5 * (t[i] + t[i + 1]) * d;
    if (glm::dot(mid, mid) <= R * R) sum += 0.5 * cross2(P, Q);
    else sum += 0.5 * R * R * std::atan2(cross2(P, Q), glm::dot(P, Q));
  }
  return sum;
}

bool sphereMeetsBox(const glm::vec3& x, float r2, const glm::vec3& lo, const glm::vec3& hi) {
  const glm::vec3 d = glm::max(glm::max(lo - x, x - hi), glm::vec3(0.f));
  return glm::dot(d, d) <= r2;
}

}  // namespace

double triangleBallArea(const glm::dvec3& a, const glm::dvec3& b, const glm::dvec3& c, const glm::dvec3& x, double r) {
  glm::dvec3 n = glm::cross(b - a, c - a);
  const double twice = glm::length(n);
  if (!(twice > 0.0) || !(r > 0.0)) return 0.0;
  n /= twice;
  const double h = glm::dot(x - a, n), R2 = r * r - h * h;
  if (!(R2 > 0.0)) return 0.0;
  // The sphere cuts the plane in the disk of radius R around x's projection.
  const glm::dvec3 p = x - h * n, u = glm::normalize(b - a), v = glm::cross(n, u);
  auto to2 = [&](const glm::dvec3& q) { return glm::dvec2(glm::dot(q - p, u), glm::dot(q - p, v)); };
  const glm::dvec2 P[3] = {to2(a), to2(b), to2(c)};
  if (glm::dot(P[0], P[0]) <= R2 && glm::dot(P[1], P[1]) <= R2 && glm::dot(P[2], P[2]) <= R2) return 0.5 * twice;
  const double R = std::sqrt(R2);
  const double s = edgeTerm(P[0], P[1], R) + edgeTerm(P[1], P[2], R) + edgeTerm(P[2], P[0], R);
  return std::clamp(std::abs(s), 0.0, 0.5 * twice);
}

GatherSurface::GatherSurface(const Scene& s) {
  const auto ok = usableFaceMask(s);
  const std::vector<glm::vec3> faceN = unitFaceNormals(s);
  std::vector<glm::vec3> centroid;
  for (size_t f = 0; f < s.faceCount(); ++f) {
    // Photons are stored on diffuse faces only.
    if (!ok[f] || isSpecular(s.faceMaterial(f))) continue;
    const auto& t = s.triangles[f];
    a_.push_back(s.positions[t.x]);
    b_.push_back(s.positions[t.y]);
    c_.push_back(s.positions[t.z]);
    m_.push_back(unpackNormal(packNormal(faceN[f])));  // as the photons on it carry it
    centroid.push_back((a_.back() + b_.back() + c_.back()) / 3.f);
  }
  order_.resize(a_.size());
  for (uint32_t i = 0; i < order_.size(); ++i) order_[i] = i;
  if (!order_.empty()) {
    nodes_.reserve(2 * order_.size() / 4 + 2);
    build(0, uint32_t(order_.size()), centroid);
  }
}

// Median split on the longest axis of the centroids' box; leaves of up to 4 faces.
uint32_t GatherSurface::build(uint32_t begin, uint32_t end, std::vector<glm::vec3>& centroid) {
  const uint32_t id = uint32_t(nodes_.size());
  nodes_.push_back({});
  glm::vec3 lo(HUGE_VALF), hi(-HUGE_VALF), clo(HUGE_VALF), chi(-HUGE_VALF);
  for (uint32_t i = begin; i < end; ++i) {
    const uint32_t f = order_[i];
    lo = glm::min(lo, glm::min(a_[f], glm::min(b_[f], c_[f])));
    hi = glm::max(hi, glm::max(a_[f], glm::max(b_[f], c_[f])));
    clo = glm::min(clo, centroid[f]);
    chi = glm::max(chi, centroid[f]);
  }
  nodes_[id].lo = lo;
  nodes_[id].hi = hi;
  if (end - begin <= 4) {
    nodes_[id].first = begin;
    nodes_[id].count = end - begin;
    return id;
  }
  const glm::vec3 ext = chi - clo;
  const int axis = ext.x >= ext.y && ext.x >= ext.z ? 0 : ext.y >= ext.z ? 1 : 2;
  const uint32_t mid = begin + (end - begin) / 2;
  std::nth_element(order_.begin() + begin, order_.begin() + mid, order_.begin() + end, [&](uint32_t p, uint32_t q) {
    return centroid[p][axis] < centroid[q][axis] || (centroid[p][axis] == centroid[q][axis] && p < q);
  });
  // The left child follows this node; `first` holds the right one.
  build(begin, mid, centroid);
  const uint32_t right = build(mid, end, centroid);
  nodes_[id].first = right;
  nodes_[id].count = 0;
  return id;
}

void GatherSurface::collect(const glm::vec3& x, const glm::vec3& n, float r, std::vector<uint32_t>& faces) const {
  faces.clear();
  if (nodes_.empty()) return;
  const float r2 = r * r;
  uint32_t stack[64];
  int top = 0;
  stack[top++] = 0;
  while (top > 0) {
    const uint32_t id = stack[--top];
    const Node& node = nodes_[id];
    if (!sphereMeetsBox(x, r2, node.lo, node.hi)) continue;
    if (node.count > 0) {
      for (uint32_t i = node.first; i < node.first + node.count; ++i) {
        const uint32_t f = order_[i];
        if (glm::dot(m_[f], n) >= kSameSide) faces.push_back(f);
      }
      continue;
    }
    stack[top++] = node.first;
    stack[top++] = id + 1;
  }
}

double GatherSurface::area(const std::vector<uint32_t>& faces, const glm::vec3& x, float r) const {
  double A = 0.0;
  for (uint32_t f : faces) A += triangleBallArea(a_[f], b_[f], c_[f], x, r);
  return A;
}

double GatherSurface::area(const glm::vec3& x, const glm::vec3& n, float r) const {
  thread_local std::vector<uint32_t> faces;
  collect(x, n, r, faces);
  return area(faces, x, r);
}

double GatherSurface::coneArea(const glm::vec3& x, const glm::vec3& n, float r, float k) const {
  thread_local std::vector<uint32_t> faces;
  collect(x, n, r, faces);
  static constexpr double node[4] = {0.1834346424956498, 0.5255324099163290, 0.7966664774136267, 0.9602898564975363};
  static constexpr double weight[4] = {0.3626837833783620, 0.3137066458778873, 0.2223810344533745, 0.1012285362903763};
  double integral = 0.0;  // int_0^r A(rho) drho
  for (int i = 0; i < 4; ++i)
    for (double sgn : {-1.0, 1.0}) integral += weight[i] * area(faces, x, float(0.5 * r * (1.0 + sgn * node[i])));
  integral *= 0.5 * r;
  return area(faces, x, r) * (1.0 - 1.0 / k) + integral / (double(k) * r);
}

}  // namespace gi

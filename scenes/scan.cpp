#include "gi/scan.h"

#include <cmath>
#include <cstdint>
#include <stdexcept>
#include <unordered_map>
#include <vector>

#include "gi/sampling.h"

namespace gi::scenes {
namespace {

using glm::dvec3;

uint64_t edgeKey(uint32_t a, uint32_t b) { return a < b ? (uint64_t(a) << 32) | b : (uint64_t(b) << 32) | a; }

struct Edge {
  uint32_t a, b;
  uint32_t opp[2] = {0, 0};
  int faces = 0;
  uint32_t mid = 0;  // index of the new vertex
};

struct Mesh {
  std::vector<dvec3> p;
  std::vector<glm::uvec3> t;
};

Mesh loopStep(const Mesh& m) {
  std::unordered_map<uint64_t, uint32_t> index;
  index.reserve(m.t.size() * 2);
  std::vector<Edge> edges;
  edges.reserve(m.t.size() * 3 / 2 + 16);
  for (const auto& t : m.t)
    for (int k = 0; k < 3; ++k) {
      const uint32_t a = t[k], b = t[(k + 1) % 3], c = t[(k + 2) % 3];
      auto [it, fresh] = index.emplace(edgeKey(a, b), uint32_t(edges.size()));
      if (fresh) edges.push_back({a, b});
      Edge& e = edges[it->second];
      if (e.faces < 2) e.opp[e.faces] = c;
      ++e.faces;
    }
  const size_t nv = m.p.size();
  Mesh out;
  out.p.resize(nv + edges.size());
  // Old vertices: the Loop mask inside, the B-spline mask along creases
  // (edges without exactly two faces), fixed at corners.
  std::vector<dvec3> ring(nv, dvec3(0.0)), crease(nv, dvec3(0.0));
  std::vector<int> valence(nv, 0), creases(nv, 0);
  for (const Edge& e : edges) {
    ring[e.a] += m.p[e.b]; ring[e.b] += m.p[e.a];
    ++valence[e.a]; ++valence[e.b];
    if (e.faces != 2) {
      crease[e.a] += m.p[e.b]; crease[e.b] += m.p[e.a];
      ++creases[e.a]; ++creases[e.b];
    }
  }
  constexpr double kPi = 3.14159265358979323846;
  for (size_t v = 0; v < nv; ++v) {
    const int n = valence[v];
    if (creases[v] == 2) {
      out.p[v] = 0.75 * m.p[v] + 0.125 * crease[v];
    } else if (creases[v] == 0 && n >= 3) {
      const double c = 0.375 + 0.25 * std::cos(2.0 * kPi / n);
      const double beta = (0.625 - c * c) / n;
      out.p[v] = (1.0 - n * beta) * m.p[v] + beta * ring[v];
    } else {
      out.p[v] = m.p[v];
    }
  }
  for (size_t i = 0; i < edges.size(); ++i) {
    Edge& e = edges[i];
    e.mid = uint32_t(nv + i);
    out.p[e.mid] = e.faces == 2 ? 0.375 * (m.p[e.a] + m.p[e.b]) + 0.125 * (m.p[e.opp[0]] + m.p[e.opp[1]])
                                : 0.5 * (m.p[e.a] + m.p[e.b]);
  }
  out.t.reserve(m.t.size() * 4);
  for (const auto& t : m.t) {
    const uint32_t ab = edges[index[edgeKey(t.x, t.y)]].mid, bc = edges[index[edgeKey(t.y, t.z)]].mid,
                   ca = edges[index[edgeKey(t.z, t.x)]].mid;
    out.t.push_back({t.x, ab, ca});
    out.t.push_back({t.y, bc, ab});
    out.t.push_back({t.z, ca, bc});
    out.t.push_back({ab, bc, ca});
  }
  return out;
}

// Improved gradient noise (Perlin 2002): gradients from the 12 cube-edge
// directions, chosen by hashing the lattice point with the seed.
double gradientNoise(const dvec3& x, uint32_t seed) {
  static const double g[12][3] = {{1, 1, 0}, {-1, 1, 0}, {1, -1, 0}, {-1, -1, 0}, {1, 0, 1}, {-1, 0, 1},
                                  {1, 0, -1}, {-1, 0, -1}, {0, 1, 1}, {0, -1, 1}, {0, 1, -1}, {0, -1, -1}};
  const dvec3 f = glm::floor(x), r = x - f;
  auto fade = [](double t) { return t * t * t * (t * (t * 6 - 15) + 10); };
  const dvec3 u(fade(r.x), fade(r.y), fade(r.z));
  double corner[8];
  for (int c = 0; c < 8; ++c) {
    const int dx = c & 1, dy = (c >> 1) & 1, dz = (c >> 2) & 1;
    const uint32_t h = hash3(uint32_t(int64_t(f.x) + dx) ^ seed, uint32_t(int64_t(f.y) + dy), uint32_t(int64_t(f.z) + dz)) % 12u;
    corner[c] = g[h][0] * (r.x - dx) + g[h][1] * (r.y - dy) + g[h][2] * (r.z - dz);
  }
  auto lerp = [](double a, double b, double t) { return a + t * (b - a); };
  const double x00 = lerp(corner[0], corner[1], u.x), x10 = lerp(corner[2], corner[3], u.x);
  const double x01 = lerp(corner[4], corner[5], u.x), x11 = lerp(corner[6], corner[7], u.x);
  return lerp(lerp(x00, x10, u.y), lerp(x01, x11, u.y), u.z);
}

Mesh toMesh(const Scene& s) {
  Mesh m;
  m.p.reserve(s.vertexCount());
  for (const auto& p : s.positions) m.p.push_back(s.toWorld(p));
  m.t = s.triangles;
  return m;
}

}  // namespace

Scene loopSubdivide(const Scene& base, int levels) {
  if (levels < 0 || levels > 8) throw std::invalid_argument("Loop subdivision levels must be 0..8");
  Mesh m = toMesh(base);
  for (int l = 0; l < levels; ++l) m = loopStep(m);
  return Scene::fromAbsolute(m.p, m.t);
}

Scene displacedScan(const Scene& base, const ScanOptions& o) {
  const Scene sub = loopSubdivide(base, o.levels);
  const std::vector<glm::vec3> n = computeVertexNormals(sub);
  dvec3 lo(1e300), hi(-1e300);
  for (const auto& p : base.positions) {
    lo = glm::min(lo, base.toWorld(p));
    hi = glm::max(hi, base.toWorld(p));
  }
  const double D = glm::length(hi - lo);
  std::vector<dvec3> pts(sub.vertexCount());
  for (size_t i = 0; i < pts.size(); ++i) {
    const dvec3 x = sub.toWorld(sub.positions[i]);
    double h = 0.0, scale = 1.0;
    for (int k = 0; k < o.octaves; ++k, scale *= 2.0)
      h += gradientNoise(x * (scale * o.frequency / D), o.seed + uint32_t(k) * 0x9e3779b9u) / scale;
    pts[i] = x + o.amplitude * D * h * dvec3(n[i]);
  }
  return Scene::fromAbsolute(pts, sub.triangles);
}

}  // namespace gi::scenes

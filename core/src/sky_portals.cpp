// Openings of the mesh to the sky, taken as portals (gi/sky.h).
//
// Found from the mesh alone: vertices at one position are welded, an edge
// used by one face only is a boundary edge, and boundary edges chained
// head to tail make loops. A loop is a portal when, after collinear corners
// are merged, it is planar and convex, no larger than Luminaires::kRectEdges
// corners, at least kMinAreaShare of the surface, no face covers it (short
// rays through its plane at points inside it hit nothing: the outline of a
// wall that is not welded to its neighbours, or a light's cut-out, is
// covered) and rays from it reach the sky on one side at least (a hole in a
// scan that leads into the scan does not). The kMaxPortals largest are kept.
// Loops left out are not lost: their sky is sampled by the cosine rays, as
// is every direction that crosses no portal.
#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdio>
#include <limits>
#include <unordered_map>
#include <unordered_set>

#include "gi/color.h"
#include "gi/luminaires.h"
#include "gi/sampling.h"
#include "gi/sky.h"
#include "hit_origin.h"

namespace gi {

namespace {

struct PosKey {
  int64_t x, y, z;
  bool operator==(const PosKey& o) const { return x == o.x && y == o.y && z == o.z; }
};
struct PosKeyHash {
  size_t operator()(const PosKey& k) const {
    return size_t(hash3(uint32_t(k.x) ^ uint32_t(k.x >> 32), uint32_t(k.y) ^ uint32_t(k.y >> 32),
                        uint32_t(k.z) ^ uint32_t(k.z >> 32)));
  }
};

// The corners of a loop with the collinear ones (within tol of the line
// through their neighbours) dropped.
std::vector<glm::dvec3> mergeCollinear(std::vector<glm::dvec3> p, double tol) {
  for (bool changed = true; changed && p.size() >= 3;) {
    changed = false;
    for (size_t k = 0; k < p.size() && p.size() >= 3; ++k) {
      const glm::dvec3 &a = p[(k + p.size() - 1) % p.size()], &b = p[k], &c = p[(k + 1) % p.size()];
      const glm::dvec3 ac = c - a;
      const double len = glm::length(ac);
      if (len > 0 && glm::length(glm::cross(ac, b - a)) <= tol * len && glm::dot(ac, b - a) > 0 &&
          glm::dot(ac, c - b) > 0) {
        p.erase(p.begin() + std::ptrdiff_t(k));
        changed = true;
        --k;
      }
    }
  }
  return p;
}

// A portal from a loop's corners, or false where it is not planar and convex.
bool planarConvex(const std::vector<glm::dvec3>& corners, SkyPortal* P) {
  const size_t m = corners.size();
  if (m < 3 || m > Luminaires::kRectEdges) return false;
  glm::dvec3 N(0.0), c(0.0);
  double diam = 0;
  for (size_t k = 0; k < m; ++k) {
    N += glm::cross(corners[k], corners[(k + 1) % m]);
    c += corners[k];
    for (size_t j = 0; j < k; ++j) diam = std::max(diam, glm::length(corners[k] - corners[j]));
  }
  c /= double(m);
  const double len = glm::length(N);
  if (!(len > 0) || !(diam > 0)) return false;
  const glm::dvec3 n = N / len;
  for (const glm::dvec3& p : corners)
    if (std::fabs(glm::dot(n, p - c)) > 1e-4 * diam) return false;
  for (size_t k = 0; k < m; ++k) {
    const glm::dvec3 &a = corners[k], &b = corners[(k + 1) % m], &d = corners[(k + 2) % m];
    if (glm::dot(glm::cross(b - a, d - b), n) < -1e-9 * diam * diam) return false;
  }
  P->corners = corners;
  P->normal = n;
  P->centre = c;
  P->area = 0.5 * len;
  return true;
}

// Point j of 16 inside the portal: on the fan triangle (centre, corner k,
// corner k + 1), kept off the outline.
glm::dvec3 insidePoint(const SkyPortal& P, uint32_t j, uint32_t key) {
  const size_t m = P.corners.size(), k = j % m;
  glm::vec2 b = uniformTriangle(glm::vec2(toUnitFloat(hash3(key, j, 1u)), toUnitFloat(hash3(key, j, 2u))));
  b = 0.1f + 0.8f * b;  // away from the corners and the outline
  const double w0 = b.x, w1 = b.y * (1.0 - b.x);
  return P.centre + w0 * (P.corners[k] - P.centre) + w1 * (P.corners[(k + 1) % m] - P.centre);
}

// The mesh's boundary as directed segments: vertices within q welded, an
// edge used by one face a boundary edge, and boundary edges on one line
// cancelled where they overlap in opposite directions (two pieces of a wall
// meshed apart, T-junctions along their seam, are closed there); what is
// left is split into maximal segments.
struct Segments {
  std::unordered_map<PosKey, std::vector<std::pair<PosKey, glm::dvec3>>, PosKeyHash> from;  // start -> ends
  std::vector<std::pair<PosKey, glm::dvec3>> starts;                                        // in a fixed order
};
Segments boundarySegments(const Scene& s, const std::vector<uint8_t>& ok, double q) {
  // Welded vertices and the edges' use counts.
  std::unordered_map<PosKey, uint32_t, PosKeyHash> idOf;
  std::vector<uint32_t> id(s.vertexCount(), kNoHit);
  std::vector<glm::dvec3> pos;
  for (size_t v = 0; v < s.vertexCount(); ++v) {
    const glm::dvec3 p(s.positions[v]);
    if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z)) continue;
    const PosKey k{std::llround(p.x / q), std::llround(p.y / q), std::llround(p.z / q)};
    const auto [it, fresh] = idOf.emplace(k, uint32_t(pos.size()));
    if (fresh) pos.push_back(p);
    id[v] = it->second;
  }
  struct Use {
    uint32_t count = 0, from = 0, to = 0;
  };
  std::unordered_map<uint64_t, Use> edges;
  edges.reserve(3 * s.faceCount());
  std::vector<uint64_t> order;  // edges in face order: deterministic loops
  for (size_t f = 0; f < s.faceCount(); ++f) {
    if (!ok[f]) continue;
    for (int e = 0; e < 3; ++e) {
      const uint32_t a = id[s.triangles[f][e]], b = id[s.triangles[f][(e + 1) % 3]];
      if (a == b || a == kNoHit || b == kNoHit) continue;
      const uint64_t key = (uint64_t(std::min(a, b)) << 32) | std::max(a, b);
      Use& u = edges[key];
      if (u.count++ == 0) { u.from = a; u.to = b; order.push_back(key); }
    }
  }
  struct Piece {
    double t0, t1;
    int sign;
  };
  struct LineKey {
    PosKey d, p;
    bool operator==(const LineKey& o) const { return d == o.d && p == o.p; }
  };
  struct LineKeyHash {
    size_t operator()(const LineKey& k) const { return PosKeyHash()(k.d) * 31u + PosKeyHash()(k.p); }
  };
  struct Line {
    glm::dvec3 d, p;
    std::vector<Piece> pieces;
  };
  std::unordered_map<LineKey, size_t, LineKeyHash> lineOf;
  std::vector<Line> lines;
  for (uint64_t key : order) {
    const Use& u = edges[key];
    if (u.count != 1) continue;
    const glm::dvec3 a = pos[u.from], b = pos[u.to];
    glm::dvec3 d = glm::normalize(b - a);
    const double lead = std::fabs(d.x) >= std::fabs(d.y) && std::fabs(d.x) >= std::fabs(d.z) ? d.x
                        : std::fabs(d.y) >= std::fabs(d.z)                                     ? d.y
                                                                                               : d.z;
    if (lead < 0) d = -d;
    const glm::dvec3 p = a - glm::dot(a, d) * d;
    const LineKey k{{std::llround(d.x * 1e6), std::llround(d.y * 1e6), std::llround(d.z * 1e6)},
                    {std::llround(p.x / q), std::llround(p.y / q), std::llround(p.z / q)}};
    const auto [it, fresh] = lineOf.emplace(k, lines.size());
    if (fresh) lines.push_back({d, p, {}});
    const Line& L = lines[it->second];
    const double ta = glm::dot(a - L.p, L.d), tb = glm::dot(b - L.p, L.d);
    lines[it->second].pieces.push_back({std::min(ta, tb), std::max(ta, tb), tb > ta ? 1 : -1});
  }
  // Segments left: directed from start to end.
  Segments out;
  auto keyOf = [&](const glm::dvec3& p) { return PosKey{std::llround(p.x / q), std::llround(p.y / q), std::llround(p.z / q)}; };
  for (const Line& L : lines) {
    std::vector<double> ts;
    for (const Piece& pc : L.pieces) { ts.push_back(pc.t0); ts.push_back(pc.t1); }
    std::sort(ts.begin(), ts.end());
    ts.erase(std::unique(ts.begin(), ts.end(), [&](double x, double y) { return std::fabs(x - y) <= q; }), ts.end());
    int runSign = 0;
    double runStart = 0;
    for (size_t i = 0; i + 1 <= ts.size(); ++i) {
      int net = 0;
      if (i + 1 < ts.size()) {
        const double mid = 0.5 * (ts[i] + ts[i + 1]);
        for (const Piece& pc : L.pieces) net += pc.t0 < mid && mid < pc.t1 ? pc.sign : 0;
        net = std::clamp(net, -1, 1);
      }
      if (net != runSign || i + 1 == ts.size()) {
        if (runSign != 0) {
          const glm::dvec3 a = L.p + runStart * L.d, b = L.p + ts[i] * L.d;
          const glm::dvec3 s0 = runSign > 0 ? a : b, s1 = runSign > 0 ? b : a;
          out.from[keyOf(s0)].push_back({keyOf(s1), s1});
          out.starts.push_back({keyOf(s0), s0});
        }
        runSign = net;
        runStart = ts[i];
      }
    }
  }
  return out;
}

// Chains of segments that close, each corner the start of one segment only.
std::vector<std::vector<glm::dvec3>> closedLoops(const Segments& sg) {
  std::vector<std::vector<glm::dvec3>> loops;
  std::unordered_set<PosKey, PosKeyHash> seen;
  for (const auto& [start, startPos] : sg.starts) {
    if (seen.count(start)) continue;
    std::vector<glm::dvec3> loop;
    bool good = true;
    PosKey v = start;
    glm::dvec3 vp = startPos;
    for (size_t steps = 0;; ++steps) {
      const auto it = sg.from.find(v);
      if (it == sg.from.end() || it->second.size() != 1 || !seen.insert(v).second || steps > 100000) {
        good = false;
        break;
      }
      loop.push_back(vp);
      vp = it->second[0].second;
      v = it->second[0].first;
      if (v == start) break;
    }
    if (good) loops.push_back(std::move(loop));
  }
  return loops;
}

// No face covers the portal (short rays through its plane at 16 points
// inside it hit nothing) and rays from it reach the sky on one side at
// least (two cosine rays to each side from each point).
bool openToTheSky(const SkyPortal& P, const RayCaster& caster, float eps, uint32_t key) {
  double diam = 0;
  for (const glm::dvec3& p : P.corners) diam = std::max(diam, 2.0 * glm::length(p - P.centre));
  const double h = 1e-3 * diam + 4.0 * double(eps);
  int escapes = 0;
  for (uint32_t j = 0; j < 16; ++j) {
    const glm::dvec3 y = insidePoint(P, j, key);
    Ray r;
    r.o = glm::vec3(y - h * P.normal);
    r.d = glm::vec3(P.normal);
    r.tfar = float(2.0 * h);
    if (caster.occluded(r)) return false;
    for (int side = -1; side <= 1; side += 2) {
      const Frame frame(glm::vec3(double(side) * P.normal));
      for (uint32_t k = 0; k < 2; ++k) {
        Ray e;
        e.o = glm::vec3(y + double(side) * h * P.normal);
        e.d = frame.toWorld(cosineHemisphere(glm::vec2(toUnitFloat(hash3(key, j, 3u + k + uint32_t(side + 1))),
                                                       toUnitFloat(hash3(key, j, 7u + k + uint32_t(side + 1))))));
        escapes += !caster.occluded(e);
      }
    }
  }
  return escapes > 0;
}

// Probe rays from up to kProbeFaces patches: how many leave the scene, and
// how many of those through no portal.
void probe(const Scene& s, const std::vector<uint8_t>& ok, const RayCaster& caster, float eps, uint32_t seed,
           SkyOpenings& out) {
  std::vector<uint32_t> faces;
  for (size_t f = 0; f < s.faceCount(); ++f)
    if (ok[f]) faces.push_back(uint32_t(f));
  const size_t stride = std::max<size_t>(1, faces.size() / size_t(SkyOpenings::kProbeFaces));
  std::atomic<uint64_t> rays{0}, escapes{0}, rest{0};
  const size_t probes = (faces.size() + stride - 1) / stride;
  parallelBlocks(probes, Progress(nullptr), "", [&](size_t b, size_t e) {
    uint64_t r = 0, esc = 0, rs = 0;
    for (size_t i = b; i < e; ++i) {
      const uint32_t f = faces[i * stride];
      const glm::vec3 n = glm::normalize(faceNormalUnnormalized(s, f));
      const PaddedSobol smp(hash3(f, seed, 0x90b1u));
      const Frame frame(n);
      const FacePoints points(s, f, n, eps, caster);
      for (int k = 0; k < SkyOpenings::kProbeRays; ++k) {
        Ray ray;
        ray.o = points.at(smp(uint32_t(k), 0)) + n * eps;
        ray.d = frame.toWorld(cosineHemisphere(smp(uint32_t(k), 1)));
        ++r;
        if (caster.occluded(ray)) continue;
        ++esc;
        rs += out.crossed(ray.o, ray.d) < 0;
      }
    }
    rays += r;
    escapes += esc;
    rest += rs;
  });
  out.probeRays = rays.load();
  out.probeEscapes = escapes.load();
  out.probeRest = rest.load();
}

}  // namespace

int SkyOpenings::crossed(const glm::vec3& o, const glm::vec3& d) const {
  const glm::dvec3 O(o), D(d);
  for (size_t i = 0; i < portals.size(); ++i) {
    const SkyPortal& P = portals[i];
    const double dn = glm::dot(D, P.normal);
    if (dn == 0) continue;
    const double t = glm::dot(P.centre - O, P.normal) / dn;
    if (!(t > 0)) continue;
    const glm::dvec3 y = O + t * D;
    bool inside = true;
    for (size_t k = 0; k < P.corners.size() && inside; ++k) {
      const glm::dvec3 &a = P.corners[k], &b = P.corners[(k + 1) % P.corners.size()];
      inside = glm::dot(glm::cross(b - a, y - a), P.normal) >= 0;
    }
    if (inside) return int(i);
  }
  return -1;
}

void SkyOpenings::report(RunStats& st) const {
  if (!any()) return;
  st.add("sky_portals", double(portals.size()));
  st.add("sky_probe_rays", double(probeRays));
  double area = 0;
  for (const SkyPortal& P : portals) area += P.area * unit * unit;
  char b[400];
  std::snprintf(b, sizeof b,
                "sky: %zu opening%s of the mesh (%.3g m^2 in all, of %zu boundary loops) lit as luminaires of the sky's "
                "radiosity; of %llu probe rays from the patches %llu left the scene, %llu outside the openings: %s",
                portals.size(), portals.size() == 1 ? "" : "s", area, loops, (unsigned long long)probeRays,
                (unsigned long long)probeEscapes, (unsigned long long)probeRest,
                rest ? "cosine rays sample the rest of the sky"
                     : probeRest ? "the rest (below 0.5% of the sky's light at 95% confidence) is left out"
                                 : "no cosine rays to the sky");
  st.note(b);
}

SkyOpenings findSkyOpenings(const Scene& s, const RayCaster& caster, const SkySun& o, uint32_t seed) {
  SkyOpenings out;
  if (!o.sky() || s.faceCount() == 0) return out;
  out.E = o.skyRadiance * float(M_PI);
  out.unit = s.unit;
  // Many emitter luminaires: the direct light samples the emitters by power
  // and takes no portals.
  if (Luminaires(s).count() > size_t(Luminaires::kMaxLuminaires)) return out;
  const auto ok = usableFaceMask(s);
  const SceneScale sc = sceneScale(s);
  const double q = 1e-6 * sc.diagonal;
  const float eps = float(sc.rayEpsilon);
  if (!(q > 0)) return out;

  double surface = 0;
  for (size_t f = 0; f < s.faceCount(); ++f)
    if (ok[f]) surface += faceArea(s, f);
  std::vector<SkyPortal> candidates;
  for (const std::vector<glm::dvec3>& loop : closedLoops(boundarySegments(s, ok, q))) {
    ++out.loops;
    double diam = 0;
    for (const glm::dvec3& p : loop) diam = std::max(diam, glm::length(p - loop[0]));
    SkyPortal P;
    if (!planarConvex(mergeCollinear(loop, 1e-5 * diam), &P)) continue;
    if (P.area < SkyOpenings::kMinAreaShare * surface) continue;
    candidates.push_back(std::move(P));
  }
  std::stable_sort(candidates.begin(), candidates.end(),
                   [](const SkyPortal& a, const SkyPortal& b) { return a.area > b.area; });
  for (const SkyPortal& P : candidates) {
    if (out.portals.size() >= SkyOpenings::kMaxPortals) break;
    double diam = 0;
    for (const glm::dvec3& p : P.corners) diam = std::max(diam, 2.0 * glm::length(p - P.centre));
    bool twin = false;  // the same opening twice (a duplicated outline)
    for (const SkyPortal& K : out.portals)
      twin = twin || (glm::length(K.centre - P.centre) < 1e-4 * diam && std::fabs(glm::dot(K.normal, P.normal)) > 0.999);
    if (!twin && openToTheSky(P, caster, eps, hash3(uint32_t(out.portals.size()), seed, 0x90a7u)))
      out.portals.push_back(P);
  }
  if (out.portals.empty()) return out;
  probe(s, ok, caster, eps, seed, out);
  // The cosine rays are left out where the light that finds another way
  // out is, at 95% confidence (a Poisson count's r + 2 sqrt(r) + 3), below
  // kRestShare of the light through the openings (a slit around a
  // recessed lamp lets a few grazing rays out).
  const double r = double(out.probeRest);
  out.rest = r > 0 && r + 2.0 * std::sqrt(r) + 3.0 > SkyOpenings::kRestShare * double(out.probeEscapes);
  return out;
}

}  // namespace gi

#include "gi/thickness.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <functional>
#include <limits>
#include <stdexcept>

#include <tbb/blocked_range.h>
#include <tbb/parallel_reduce.h>

#include "gi/sampling.h"

namespace gi {
namespace {

constexpr int kRound = 32;  // rays per adaptive round, as AO

void checkOptions(const ThicknessOptions& o) {
  if (o.raysPerVertex < 1) throw std::invalid_argument("rays_per_vertex must be >= 1");
  if (!(o.targetError >= 0.0) || !std::isfinite(o.targetError))
    throw std::invalid_argument("target_error must be a finite number >= 0");
  if (o.targetError > 0.0 && (o.minRays < 1 || o.maxRays < 1))
    throw std::invalid_argument("min_rays and max_rays must be >= 1");
  if (o.targetError > 0.0 && o.minRays > o.maxRays)
    throw std::invalid_argument("min_rays (" + std::to_string(o.minRays) + ") exceeds max_rays (" +
                                std::to_string(o.maxRays) + ")");
  if (!(o.coneAngleDeg > 0.f && o.coneAngleDeg < 90.f))
    throw std::invalid_argument("cone_angle must lie between 0 and 90 degrees");
}

struct VertexThickness {
  float value = 0.f, stdError = 0.f;
  int rays = 0, hits = 0, ownFaces = 0;
};

// The faces at each vertex's position (its own and those of other vertices
// at the same point, as an unwelded mesh has them), one sorted list per
// position: faces[start[g], start[g + 1]) for g = group[v] (a list per
// vertex cost k^2 at a point k unwelded faces share; a review).
struct FacesAtVertex {
  std::vector<uint32_t> group, start, faces;
  const uint32_t* begin(size_t v) const { return faces.data() + start[group[v]]; }
  const uint32_t* end(size_t v) const { return faces.data() + start[group[v] + 1]; }
};

class ThicknessKernel {
 public:
  ThicknessKernel(const RayCaster& c, const ThicknessOptions& o)
      : caster_(c), o_(o), sinAlpha_(std::sin(glm::radians(o.coneAngleDeg))) {}

  // Rays from origin `org` (just inside the surface at vertex p) in the cone around -n.
  VertexThickness run(uint32_t vi, const glm::vec3& p, const glm::vec3& org, const glm::vec3& n,
                      const uint32_t* ownBegin, const uint32_t* ownEnd, std::vector<float>& lengths,
                      std::vector<float>& scratch) const {
    VertexThickness out;
    const Frame frame(-n);
    SobolOwenStream seq(hash3(vi, o_.seed, 0x5dfu));
    const bool adaptive = o_.targetError > 0.0;
    const int maxN = adaptive ? o_.maxRays : o_.raysPerVertex;
    float u0[kRound], u1[kRound], lx[kRound], ly[kRound], lz[kRound];
    Ray rays[kRound];
    Hit hits[kRound];
    lengths.clear();
    RobustMean rm;
    int done = 0, nextTest = 0;
    while (done < maxN) {
      const int m = std::min(kRound, maxN - done);
      seq.nextBlock(m, u0, u1);
      // Cosine-weighted in the cone: the concentric disk point scaled by sin(alpha), lifted to the sphere.
      cosineHemisphereBlock(m, u0, u1, lx, ly, lz);
      for (int j = 0; j < m; ++j) {
        const float x = lx[j] * sinAlpha_, y = ly[j] * sinAlpha_;
        const float z = std::sqrt(std::max(0.f, 1.f - x * x - y * y));
        rays[j].o = org;
        rays[j].d = frame.t * x + frame.b * y + frame.n * z;
        rays[j].tnear = 0.f;
        rays[j].tfar = std::numeric_limits<float>::infinity();
      }
      caster_.intersectBatch(rays, size_t(m), hits);
      for (int j = 0; j < m; ++j) {
        // Leaving the object: the face met faces along the ray (its back is
        // seen), or, where two solids touch, a face whose reversed copy (the
        // other solid's) the caster reported instead of its back.
        if (!hits[j].valid()) continue;
        if (!(glm::dot(hits[j].ng, rays[j].d) > 0.f) && caster_.reversedCopy(hits[j].face) == kNoHit) continue;
        // Leaving through a face at the vertex itself is no chord of the
        // object: at a convex corner the cone reaches past the faces that
        // meet there (a cube's corner: beyond 35 degrees of the diagonal),
        // and those rays left within a ray offset. Where the far side was
        // open they outnumbered the chords and the robust mean read them: an
        // unwelded block's top corners 0.01 to 0.2 for about 60, which copy
        // depending on the vertex order (an outside audit).
        if (std::binary_search(ownBegin, ownEnd, hits[j].face)) { ++out.ownFaces; continue; }
        // The chord from where the ray's line crosses the vertex's tangent
        // plane: the origin lies eps inside it (or pulled into a face), so
        // t alone is short by eps / cos theta, and the distance from the
        // vertex to the exit, sqrt(1 + (1 - eps)^2 tan^2 theta) on a slab of
        // thickness 1, too (eps is 1e-5 of the scene's size: 4% low at 60
        // degrees on a slab 1 thick and 6,000 wide).
        const float cosd = glm::dot(n, rays[j].d);  // below 0: into the object
        const glm::vec3 q = rays[j].o + hits[j].t * rays[j].d;
        lengths.push_back(cosd < -1e-6f ? hits[j].t + glm::dot(n, org - p) / cosd : glm::length(q - p));
      }
      done += m;
      if (!adaptive || done < o_.minRays || done < nextTest) continue;
      // The robust mean sorts every length so far: tested after each round up
      // to 1,024 rays, then after each eighth more, so that a large max_rays
      // costs n log n, not n^2 (262,144 rays took over 200 s a vertex).
      if (done >= 1024) nextTest = done + std::max(kRound, done / 8 / kRound * kRound);
      scratch = lengths;
      rm = robustMean(scratch, o_.rejectOutliers);
      if (rm.count >= 2 && rm.stdError <= o_.targetError * rm.mean) break;
    }
    scratch = lengths;
    rm = robustMean(scratch, o_.rejectOutliers);
    out.rays = done;
    out.hits = int(lengths.size());
    out.value = float(rm.mean);
    out.stdError = float(rm.stdError);
    return out;
  }

 private:
  const RayCaster& caster_;
  const ThicknessOptions& o_;
  float sinAlpha_;
};

// Vertices at one position share a group (exact float positions, -0 and +0
// as one); a non-finite position, which no usable face has, is a group of
// its own. Both the normals' welding and the faces at a vertex use them.
struct PositionGroups {
  std::vector<uint32_t> group;
  uint32_t count = 0;
};

PositionGroups positionGroups(const Scene& scene) {
  const size_t nv = scene.vertexCount();
  PositionGroups g;
  g.group.assign(nv, 0);
  std::vector<uint32_t> order;
  order.reserve(nv);
  for (size_t i = 0; i < nv; ++i)
    if (finite3(scene.positions[i])) order.push_back(uint32_t(i));
    else g.group[i] = g.count++;
  auto key = [&](uint32_t i) {
    const glm::vec3& p = scene.positions[i];
    return std::array<float, 3>{p.x + 0.f, p.y + 0.f, p.z + 0.f};
  };
  std::sort(order.begin(), order.end(), [&](uint32_t a, uint32_t b) { return key(a) < key(b); });
  for (size_t k = 0; k < order.size(); ++k) {
    if (k > 0 && key(order[k]) != key(order[k - 1])) ++g.count;
    g.group[order[k]] = g.count;
  }
  if (!order.empty()) ++g.count;
  return g;
}

// Whether each vertex's own faces (by index) close around it: every
// neighbour it has through an edge is on two of its faces. Only vertices
// at a position shared with others are asked (`ask`).
std::vector<uint8_t> closedFans(const Scene& scene, const std::vector<uint8_t>& ask) {
  const size_t nv = scene.vertexCount();
  std::vector<uint32_t> start(nv + 1, 0);
  for (const glm::uvec3& t : scene.triangles)
    if (t.x < nv && t.y < nv && t.z < nv)
      for (int c = 0; c < 3; ++c) start[t[c] + 1] += ask[t[c]] ? 2 : 0;
  for (size_t i = 0; i < nv; ++i) start[i + 1] += start[i];
  std::vector<uint32_t> next(start.begin(), start.end() - 1), around(start[nv]);
  for (const glm::uvec3& t : scene.triangles)
    if (t.x < nv && t.y < nv && t.z < nv)
      for (int c = 0; c < 3; ++c)
        if (ask[t[c]]) around[next[t[c]]++] = t[(c + 1) % 3], around[next[t[c]]++] = t[(c + 2) % 3];
  std::vector<uint8_t> closed(nv, 0);
  for (size_t i = 0; i < nv; ++i) {
    if (!ask[i] || start[i] == start[i + 1]) continue;
    std::sort(around.begin() + start[i], around.begin() + start[i + 1]);
    bool twice = true;
    for (uint32_t k = start[i]; twice && k < start[i + 1]; k += 2)
      twice = around[k] == around[k + 1] && (k + 2 == start[i + 1] || around[k + 2] != around[k]);
    closed[i] = twice;
  }
  return closed;
}

// Vertices at one position whose own faces leave it open take one normal,
// the sum of theirs: the solid's inward direction there, which is what the
// shape diameter measures (a mesh with its faces unwelded gives each corner
// of a cube the normal of one face, whose cone met the neighbouring faces at
// the corner: thickness 0.0003 where the welded cube reads 2.46; an outside
// audit). A vertex whose faces close around it is a welded solid's and
// keeps its normal: two solids touching at a vertex (a cube standing on a
// slab, corner on vertex; two cubes stacked, their shared face a reversed
// copy) took each other's normals there, the corners 1.97 to 2.17 where the
// cube alone reads 1.23 and the contact face's rim 0 (a later audit).
void weldNormals(const Scene& scene, const PositionGroups& g, std::vector<glm::vec3>& normals) {
  std::vector<uint32_t> atPosition(g.count, 0);
  for (size_t i = 0; i < normals.size(); ++i) ++atPosition[g.group[i]];
  std::vector<uint8_t> shared(normals.size(), 0);
  for (size_t i = 0; i < normals.size(); ++i) shared[i] = atPosition[g.group[i]] > 1;
  const std::vector<uint8_t> closed = closedFans(scene, shared);
  std::vector<glm::dvec3> sum(g.count, glm::dvec3(0.0));
  std::vector<uint32_t> members(g.count, 0);
  auto has = [&](size_t i) { return shared[i] && !closed[i] && glm::dot(normals[i], normals[i]) > 0.5f; };
  for (size_t i = 0; i < normals.size(); ++i)
    if (has(i)) {
      sum[g.group[i]] += glm::dvec3(normals[i]);
      ++members[g.group[i]];
    }
  for (size_t i = 0; i < normals.size(); ++i) {
    const uint32_t k = g.group[i];
    if (!has(i) || members[k] < 2) continue;
    const double l = glm::length(sum[k]);
    // Normals that cancel (a two-sided surface's own vertices) keep theirs.
    if (l > 1e-3) normals[i] = glm::vec3(sum[k] / l);
  }
}

FacesAtVertex facesAtVertices(const Scene& scene, const PositionGroups& g) {
  const size_t nv = scene.vertexCount();
  FacesAtVertex out;
  out.start.assign(size_t(g.count) + 1, 0);
  for (const glm::uvec3& t : scene.triangles)
    for (int c = 0; c < 3; ++c)
      if (t[c] < nv) ++out.start[g.group[t[c]] + 1];
  for (size_t k = 0; k < g.count; ++k) out.start[k + 1] += out.start[k];
  out.faces.resize(out.start[g.count]);
  std::vector<uint32_t> fill(out.start.begin(), out.start.end() - 1);
  for (size_t f = 0; f < scene.triangles.size(); ++f)  // in face order: each group's list comes out sorted
    for (int c = 0; c < 3; ++c)
      if (scene.triangles[f][c] < nv) out.faces[fill[g.group[scene.triangles[f][c]]]++] = uint32_t(f);
  out.group = g.group;
  return out;
}

std::string num(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.3g", v);
  return buf;
}

}  // namespace

RobustMean robustMean(std::vector<float>& L, bool reject) {
  RobustMean r;
  const size_t n = L.size();
  if (n == 0) return r;
  auto meanOf = [](const float* b, const float* e, double& mean, double& sd) {
    const double k = double(e - b);
    double s = 0, ss = 0;
    for (const float* x = b; x != e; ++x) s += *x;
    mean = s / k;
    for (const float* x = b; x != e; ++x) ss += (*x - mean) * (*x - mean);
    sd = k > 1 ? std::sqrt(ss / (k - 1)) : 0.0;
  };
  double mean, sd;
  meanOf(L.data(), L.data() + n, mean, sd);
  const float* b = L.data();
  const float* e = L.data() + n;
  if (reject && n >= 3) {
    std::sort(L.begin(), L.end());
    const double median = n % 2 ? L[n / 2] : 0.5 * (double(L[n / 2 - 1]) + L[n / 2]);
    const float* lo = L.data() + (std::lower_bound(L.begin(), L.end(), float(median - sd)) - L.begin());
    const float* hi = L.data() + (std::upper_bound(L.begin(), L.end(), float(median + sd)) - L.begin());
    if (hi - lo >= 1) {
      b = lo;
      e = hi;
      meanOf(b, e, mean, sd);
      // The standard error of a trimmed mean: the winsorised sample's
      // standard deviation (the values cut off set to the nearest kept one)
      // over (k / n) sqrt(n), k of n kept (Tukey and McLaughlin 1963). The
      // kept values' own spread over sqrt(k) ignores that the window was
      // chosen from the same sample: at 16 rays per vertex the z-scores of
      // a sphere's thickness had an RMS of 1.77, 6.5% beyond 3 (an outside audit).
      const size_t k = size_t(e - b);
      double ws = 0, wss = 0;
      for (size_t i = 0; i < n; ++i) {
        const double x = std::clamp(double(L[i]), double(*b), double(*(e - 1)));
        ws += x;
        wss += x * x;
      }
      const double wmean = ws / double(n), wvar = std::max(0.0, (wss - double(n) * wmean * wmean) / double(n - 1));
      r.count = k;
      r.mean = mean;
      r.stdError = std::sqrt(wvar) * std::sqrt(double(n)) / double(k);
      return r;
    }
  }
  r.count = size_t(e - b);
  r.mean = mean;
  // One length says nothing of its spread: its error is taken as its whole
  // value (an outside audit: one ray per vertex reported 0, "exact", where
  // the lengths of a slab spread over 26% of the value).
  r.stdError = r.count > 1 ? sd / std::sqrt(double(r.count)) : std::fabs(mean);
  return r;
}

namespace {

// The unmeasured vertices whose opposite side lies within the ray offset:
// the rays start past it, so a plate thinner than the offset reads 0, which
// the log blamed on an open mesh or inward normals (an outside audit: a
// closed 10 x 10 x t box at t = 0.9 of the offset read 0 at all 242
// vertices of its middle). One ray each, inwards from the vertex itself.
size_t thinnerThanTheOffset(const Scene& scene, const RayCaster& caster, const std::vector<glm::vec3>& normals,
                            const std::vector<uint8_t>& valid, const std::vector<int>& hits, float eps) {
  return tbb::parallel_reduce(
      tbb::blocked_range<size_t>(0, scene.vertexCount()), size_t(0),
      [&](const tbb::blocked_range<size_t>& range, size_t thin) {
        for (size_t i = range.begin(); i != range.end(); ++i) {
          if (!valid[i] || hits[i] != 0) continue;
          Ray r;
          r.o = scene.positions[i];
          r.d = -normals[i];
          r.tnear = 0.05f * eps;  // past the vertex's own faces
          r.tfar = 2.f * eps;
          const Hit h = caster.intersect(r);
          thin += h.valid() && glm::dot(r.d, h.ng) > 0.f;
        }
        return thin;
      },
      std::plus<size_t>());
}

}  // namespace

ThicknessResult computeThickness(const Scene& scene, const RayCaster& caster, const ThicknessOptions& opt,
                                 const Progress& progress) {
  checkCasterFor(scene, caster);
  checkOptions(opt);
  Timer timer;
  const SceneReport rep = analyzeScene(scene);
  if (rep.usableFaces() == 0) throw std::invalid_argument("the mesh has no usable triangles (" + rep.summary() + ")");
  const size_t nv = scene.vertexCount();
  const PositionGroups groups = positionGroups(scene);
  std::vector<glm::vec3> normals = vertexNormalsForRays(scene);
  weldNormals(scene, groups, normals);
  std::vector<glm::vec3> inward(nv);
  for (size_t i = 0; i < nv; ++i) inward[i] = -normals[i];
  // Origins just inside the surface (and into the incident faces at borders).
  const std::vector<glm::vec3> origins = vertexRayOrigins(scene, inward, float(rep.rayEpsilon));
  ThicknessResult res;
  res.value.assign(nv, 0.f);
  res.stdError.assign(nv, 0.f);
  res.rays.assign(nv, 0);
  res.hits.assign(nv, 0);
  std::vector<uint8_t> valid(nv, 0);
  for (size_t i = 0; i < nv; ++i) {
    const glm::vec3& p = scene.positions[i];
    const glm::vec3& n = normals[i];
    valid[i] = finite3(p) && finite3(n) &&
               glm::dot(n, n) > 0.5f;
  }
  const ThicknessKernel kernel(caster, opt);
  const FacesAtVertex at = facesAtVertices(scene, groups);
  std::vector<int> ownExits(nv, 0);
  Timer traceTimer;
  parallelBlocks(nv, progress, "casting rays", [&](size_t b, size_t e) {
    std::vector<float> lengths, scratch;
    for (size_t i = b; i < e; ++i) {
      if (!valid[i]) continue;
      const VertexThickness t = kernel.run(uint32_t(i), scene.positions[i], origins[i], normals[i], at.begin(i),
                                           at.end(i), lengths, scratch);
      ownExits[i] = t.ownFaces;
      res.value[i] = float(t.value * scene.unit);  // world units (Scene::unit)
      res.stdError[i] = float(t.stdError * scene.unit);
      res.rays[i] = t.rays;
      res.hits[i] = t.hits;
    }
  });
  const double traceSeconds = traceTimer.seconds();
  // Summary (sequential: deterministic).
  // A vertex with nothing measured reads 0 with an error bar of the scene's
  // diagonal (anything up to its size), not 0 +- 0, which read as an exact
  // thickness of 0 (an outside audit).
  double rays = 0, sum = 0, relVar = 0;
  size_t counted = 0, invalid = 0, noHit = 0, few = 0;
  const float unknown = float(rep.diagonal);
  for (size_t i = 0; i < nv; ++i) {
    rays += res.rays[i];
    if (!valid[i]) { ++invalid; res.stdError[i] = unknown; continue; }
    if (res.hits[i] == 0) { ++noHit; res.stdError[i] = unknown; continue; }
    if (res.hits[i] * 2 < res.rays[i]) ++few;
    sum += res.value[i];
    if (res.value[i] > 0.f) relVar += double(res.stdError[i]) * res.stdError[i] / (double(res.value[i]) * res.value[i]);
    ++counted;
  }
  auto& st = res.stats;
  st.add("vertices", double(nv));
  st.add("rays", rays);
  st.add("seconds", timer.seconds());
  st.add("rays_per_second", traceSeconds > 0 ? rays / traceSeconds : 0.0);
  st.add("mean_of_measured", counted ? sum / double(counted) : 0.0);  // no_opposite_side vertices left out (they read 0)
  st.add("rms_relative_error_estimate", counted ? std::sqrt(relVar / double(counted)) : 0.0);
  st.add("no_opposite_side", double(noHit));
  double ownRays = 0;
  for (int k : ownExits) ownRays += k;
  st.add("rays_leaving_at_the_vertex", ownRays);
  if (ownRays > 0)
    st.note(num(ownRays) + " rays left through a face at their own vertex (the cone reaches past a convex corner "
            "or edge): no chord, not counted");
  st.add("skipped_invalid", double(invalid));
  size_t unmeasured = invalid;
  unmeasured -= copyOnlyAmong(scene, [&](size_t i) { return !valid[i]; });
  if (unmeasured) st.note(std::to_string(unmeasured) + " vertices without a usable face, with NaN/Inf, or without a normal (on a two-sided "
                          "surface, each face with a reversed copy, the faces' normals cancel) got 0, with the scene's diagonal as their StdError");
  if (noHit)
    st.note(std::to_string(noHit) + " vertices found no opposite side (every ray missed or met a front face) and got 0, "
            "with the scene's diagonal as their StdError (unmeasured)");
  const float eps = float(rep.rayEpsilon);
  const size_t thin = thinnerThanTheOffset(scene, caster, normals, valid, res.hits, eps);
  if (thin) {
    char b[360];
    std::snprintf(b, sizeof b,
                  "%zu unmeasured vertices have the back of a face within twice the ray offset (%.3g) behind "
                  "them: a part thinner than the offset (1e-5 of the scene's size) reads 0 there",
                  thin, double(eps) * scene.unit);
    st.warn(b);
  }
  const size_t traced = nv - invalid;
  // (Not when most of the vertices that found nothing are explained by a
  // part thinner than the offset, warned of above; an open mesh whose every
  // vertex still finds something was never warned of: `thin * 2 < noHit`
  // read 0 < 0, an outside audit.)
  if (traced && (noHit + few) * 10 > traced && thin * 2 <= noHit)
    st.warn(std::to_string(noHit + few) + " of " + std::to_string(traced) +
            " vertices found the opposite side with fewer than half their rays (" + std::to_string(noHit) +
            " with none): the mesh is open, its normals point inwards, or it has inner shells; thickness is "
            "measured only where rays leave through the back of a face");
  // The robust mean's window (median +- sd) comes from the same few lengths:
  // from 16 rays its error bars hold (a sphere's z-scores: RMS 1.19 at 16,
  // 0.62 at 32 rays), below they understate the error (1.95 at 8).
  const int fewest = opt.targetError > 0.0 ? std::min(opt.minRays, opt.maxRays) : opt.raysPerVertex;
  if (fewest < 2)
    st.warn(std::string(opt.targetError > 0.0 ? "min_rays " : "rays_per_vertex ") +
            "1: one length per vertex has no error estimate; its standard error is reported as the value itself");
  else if (opt.rejectOutliers && fewest < kRobustMinRays)
    st.warn(std::string(opt.targetError > 0.0 ? "min_rays " : "rays_per_vertex ") + std::to_string(fewest) +
            " is below " + std::to_string(kRobustMinRays) +
            " with reject_outliers: the robust mean's window is estimated from too few lengths, and its "
            "standard errors understate the error (and its value is biased, a few percent at 8 rays)");
  if (opt.targetError > 0.0) {
    size_t unmet = 0;
    for (size_t i = 0; i < nv; ++i)
      if (res.hits[i] && res.rays[i] >= opt.maxRays && res.stdError[i] > opt.targetError * res.value[i]) ++unmet;
    if (unmet * 10 > counted)
      st.warn(std::to_string(unmet) + " of " + std::to_string(counted) + " vertices stopped at max_rays " +
              std::to_string(opt.maxRays) + " with their relative standard error above target_error " +
              num(opt.targetError) + ": raise max_rays or the target");
  }
  return res;
}

}  // namespace gi

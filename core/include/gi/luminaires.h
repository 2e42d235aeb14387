// Luminaires: the emitter triangles grouped into planar polygons of one
// emission, and the direct irradiance they give a point as an exact form
// factor times a visibility fraction.
//
// Grouping: emitter triangles that share an edge (the same two vertex
// indices), emit the same radiosity and lie in one plane (every vertex of
// the group within kPlaneTolerance x the scene's diagonal of the group's
// area-weighted plane) are one luminaire (union-find over the shared
// edges). A connected group that is not planar (a curved or noisy emitting
// surface) is left as one luminaire per triangle.
//
// Irradiance at x (unit normal n) from a luminaire L of emitted radiosity E_L:
//   H_L(x) = E_L F(x -> L) V(x, L),
// F the unoccluded point-to-polygon form factor, Lambert's contour integral
// over L's boundary (Lambert 1760; Baum, Rushmeier and Winget 1989),
//   F = 1/(2 pi) |sum_k Theta_k n . (v_k x v_k+1) / |v_k x v_k+1||,  v_k = p_k - x,
// the sum over the directed boundary edges (p_k, p_k+1) of the union: an
// edge shared by two of its triangles cancels, so holes and non-convex
// outlines need no ordering. Where L straddles x's tangent plane the sum is
// taken per triangle, each clipped to the half-space in front of x
// (pointToTriangleFormFactor). V is the form-factor-weighted visible
// fraction,
//   V = int_L k(x,y) vis(x,y) dA_y / int_L k(x,y) dA_y,  k = cos(theta_x) cos(theta_y) / r^2,
// estimated from m shadow rays to points y_j stratified over L's area (an
// Owen-scrambled Sobol sequence, every power-of-two prefix of which is
// stratified, mapped onto L's bounding rectangle in its plane, the points
// outside L dropped; for an outline of many edges or one filling less than
// a quarter of that rectangle, mapped through L's area CDF over its
// triangles instead) by the ratio
//   V_m = sum_j k_j vis_j / sum_j k_j,
// exact (1 or 0) wherever the rays agree. First kFirstRays rays, and where
// they agree, one ray to each of up to kProbes corners of L (a straight
// occluder edge hides a part of a convex polygon that holds a corner, however
// thin that part is; these rays only detect, they do not enter V); where
// some but not all are blocked (penumbra) the stratified sequence is
// continued to the point's ray budget. Its standard error (delta method for a ratio),
//   se(V_m) = sqrt(sum_j k_j^2 (vis_j - V_m)^2) / sum_j k_j,
// is 0 where the rays agree. That is a statement about the sample, not a
// bound: if a fraction e of L (weighted by k) is hidden, m independent rays
// all pass with probability (1 - e)^m <= exp(-e m), so a unanimous verdict
// leaves, at 95% confidence, a blocked fraction below 1 - 0.05^(1/m),
// about 3/m (the "rule of three": 17% for 16 rays, 4.6% for 64).
// Stratification lowers the chance of missing an occluder that covers whole
// strata, and the corner rays catch the shadow of a straight edge; an
// occluder smaller than a stratum that covers no corner (a thin pole
// across the light) is what the first stage can miss.
//
// With more than kMaxLuminaires luminaires (a scan whose emitting surface is
// curved or noisy), the direct light keeps power-proportional sampling of
// the emitter triangles (EmitterSampler, gi/emitters.h).
#pragma once
#include <algorithm>
#include <array>
#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include "gi/form_factor_analytic.h"
#include "gi/scene.h"

namespace gi {

class RayCaster;
struct SkyOpenings;

// Inverts a cumulative table (non-decreasing, last entry the total) at
// x = u * total: the entry k with cdf[k-1] <= x < cdf[k], and in *rescaled
// where x falls within it, in [0, 1) (0.5 for an empty entry), so that u's
// remaining digits can be reused (a luminaire's triangles by area, the
// emitter triangles by power in EmitterSampler).
inline size_t invertCdf(const std::vector<double>& cdf, double u, float* rescaled) {
  const double x = u * cdf.back();
  size_t k = size_t(std::upper_bound(cdf.begin(), cdf.end(), x) - cdf.begin());
  k = std::min(k, cdf.size() - 1);
  const double lo = k ? cdf[k - 1] : 0.0, w = cdf[k] - lo;
  *rescaled = w > 0 ? float(std::clamp((x - lo) / w, 0.0, 0.99999994)) : 0.5f;
  return k;
}

struct Luminaire {
  std::vector<uint32_t> faces;                          // its emitter triangles
  std::vector<std::array<glm::dvec3, 2>> boundary;      // directed boundary edges (front: counter-clockwise)
  std::vector<glm::dvec3> corners;                      // the boundary edges' end points
  std::vector<glm::dvec3> probes;                       // up to kProbes corners, pulled 1e-3 towards the centre
  std::vector<double> cdf;                              // cumulative area over faces
  // Its bounding rectangle in its plane (sides along u and v, u along the
  // longest boundary edge), and the boundary edges in (u, v): points are
  // drawn in the rectangle, those outside the polygon dropped, where that
  // keeps at least a quarter and the boundary has at most kRectEdges edges.
  glm::dvec3 rectCorner{0.0}, u{0.0}, v{0.0};           // u, v: the sides (lengths included)
  std::vector<std::array<glm::dvec2, 2>> outline;       // boundary in rectangle coordinates [0,1]^2
  bool rect = false;
  glm::dvec3 normal{0.0};                               // unit, the emitting side
  glm::dvec3 origin{0.0};                               // a point of its plane
  glm::vec3 E{0.f};                                     // emitted radiosity (RGB, W/m^2)
  double area = 0.0;
  // An opening to the sky (gi/sky.h): no faces of its own but the fan of
  // its outline in `tris`; seen from both sides; its shadow rays must leave
  // the scene, and count only for the lowest-index portal they cross.
  bool portal = false;
  std::vector<std::array<glm::dvec3, 3>> tris;
};

class Luminaires {
 public:
  static constexpr int kMaxLuminaires = 256;   // more: power sampling
  static constexpr double kPlaneTolerance = 1e-6;  // x the scene's diagonal
  static constexpr int kFirstRays = 16;        // shadow rays per luminaire before penumbra refinement
  static constexpr size_t kProbes = 8;         // corner rays that may reveal a penumbra the first rays missed
  static constexpr size_t kRectEdges = 64;     // boundary edges at most for drawing points in the bounding rectangle

  explicit Luminaires(const Scene& s);
  // The openings' portals alone, as luminaires of the sky's radiosity
  // (`openings` must outlive this).
  Luminaires(const Scene& s, const SkyOpenings& openings);
  const std::vector<Luminaire>& list() const { return lum_; }
  size_t count() const { return lum_.size(); }
  size_t emitterFaces() const { return faces_; }
  // The luminaire method applies: some emitters (or sky portals) and at most kMaxLuminaires luminaires.
  bool usable() const { return !lum_.empty() && lum_.size() <= size_t(kMaxLuminaires); }
  size_t portals() const { return lum_.size() - firstPortal_; }
  // A shadow ray from x along w that reached luminaire L (and, for a portal,
  // left the scene) counts for L: always for an emitter; for a portal, when
  // L is the lowest-index portal the ray crosses.
  bool counts(size_t L, const glm::vec3& x, const glm::vec3& w) const;

  // Unoccluded F from the point x (unit normal n) to luminaire L; 0 behind L's plane.
  double formFactor(size_t L, const glm::dvec3& x, const glm::dvec3& n) const;
  // L as the target of a mean of formFactor over a patch (meanOverTriangle).
  FormFactorTarget target(size_t L) const;
  // A point of L for u in [0,1)^2, uniform over its area; false where u
  // falls outside the polygon in its bounding rectangle (Luminaire::rect).
  bool point(size_t L, glm::vec2 u, glm::vec3* y) const;

 private:
  const Scene& s_;
  std::vector<Luminaire> lum_;
  size_t faces_ = 0;
  size_t firstPortal_ = 0;
  const SkyOpenings* openings_ = nullptr;
  void addPortals(const SkyOpenings& openings);
  double planeTol_ = 0.0;
};

struct LuminaireEstimate {
  glm::vec3 H{0.f};      // irradiance
  double stdError = 0;   // standard error of luminance(H) (0 where every luminaire's rays agree)
  uint32_t rays = 0;     // shadow rays cast
  bool penumbra = false; // some luminaire's rays disagreed
};

// Per luminaire, the sums over a patch's points of F(x -> L) and of
// F(x -> L) V(x, L): their ratio is L's visibility from the patch, weighted
// as its light arrives (patchDirectIrradiance).
struct LuminaireSums {
  std::vector<double> F, FV;
  explicit LuminaireSums(size_t count = 0) : F(count, 0.0), FV(count, 0.0) {}
};

// H(x) = sum_L E_L F(x -> L) V(x, L) at the surface point x (unit normal n;
// its shadow rays start at `from`, x lifted off its surface: F taken at the
// lifted point read eps / h low for a luminaire at height h, an outside
// audit): kFirstRays rays per luminaire, continued to `budget` rays (at
// least kFirstRays) for a luminaire in penumbra; no rays when `unoccluded`
// (nothing in the scene can block). Random numbers keyed by key. Luminaire
// `skip` (the one x lies on, if any) is left out. sums (optional): F and
// F V of each luminaire added.
LuminaireEstimate luminaireIrradiance(const Luminaires& lums, const RayCaster& caster, const glm::vec3& x,
                                      const glm::vec3& from, const glm::vec3& n, int budget, uint32_t key, float eps,
                                      bool unoccluded,
                                      uint32_t skip = 0xffffffffu, LuminaireSums* sums = nullptr);

}  // namespace gi

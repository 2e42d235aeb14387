// The two-pass mode's caustic map: Jensen's density estimate read at eye-
// ray hit points (Jensen 1996; the cone filter of "Realistic Image Synthesis
// Using Photon Mapping", 2001, sec. 7.2.2):
//   H(x) ~ sum_p w_p Phi_p / ((1 - 2 / (3 c)) pi r^2),   w_p = 1 - d_p / (c r),  c = 1.1,
// over the k nearest caustic photons on the side of n, r the distance to the
// k-th (or the gather radius if fewer lie within it), the disk's weighted
// area (1 - 2 / (3 c)) pi r^2 replaced by the cone's integral over the
// surface actually inside the sphere (GatherSurface::coneArea): half of it
// at a crease, part of it at a mesh border, where the full disk had read
// the caustic 8 to 22% low (an outside audit, 6 December 2026), and the
// default mode, which takes the map's value at the border vertices out of
// the first pass (photon mapping, whose map has that area), left 20 to 28%
// too much there. The nearest-neighbour
// search is bounded by the gather radius from the start, so that a hit far
// from every caustic (most of an image) costs a short descent, not a search
// of the whole tree; the estimate itself is that of the photon-mapping
// filter's caustic map.
#include <algorithm>
#include <cmath>

#include "gi/color.h"
#include "photon_surface.h"
#include "point_cloud.h"
#include "render_internal.h"

namespace gi::eye {

struct CausticMap::Impl {
  explicit Impl(const Scene& s) : surface(s) {}
  GatherSurface surface;
  std::vector<Photon> photons;
  PointCloud cloud;
  std::unique_ptr<PointTree> tree;
};

CausticMap::CausticMap(std::vector<Photon> photons, const Scene& s) : impl_(std::make_unique<Impl>(s)) {
  impl_->photons = std::move(photons);
  impl_->cloud.pts.reserve(impl_->photons.size());
  for (const Photon& p : impl_->photons) impl_->cloud.pts.push_back(p.p);
  impl_->tree = std::make_unique<PointTree>(3, impl_->cloud, nanoflann::KDTreeSingleIndexAdaptorParams(16));
  impl_->tree->buildIndex();
}

CausticMap::~CausticMap() = default;

size_t CausticMap::size() const { return impl_->photons.size(); }

glm::vec3 CausticMap::irradiance(const glm::vec3& x, const glm::vec3& n, int k, float r2max) const {
  constexpr size_t kMaxQuery = 1024;
  if (size() == 0 || k < 1) return glm::vec3(0.f);
  // More than k: photons on the other side of the surface are dropped.
  const size_t want = std::min<size_t>({size(), size_t(k) * 2, kMaxQuery});
  uint32_t idx[kMaxQuery];
  float d2[kMaxQuery];
  nanoflann::KNNResultSet<float, uint32_t> result(want);
  result.init(idx, d2);
  if (r2max < HUGE_VALF) d2[want - 1] = r2max;  // the search's bound until `want` are found
  const float q[3] = {x.x, x.y, x.z};
  impl_->tree->findNeighbors(result, q, nanoflann::SearchParams());
  const size_t found = result.size();
  if (found == 0) return glm::vec3(0.f);
  int used = 0;
  const Photon* ph[kMaxQuery];
  float dd[kMaxQuery];
  for (size_t m = 0; m < found && used < k; ++m) {
    const Photon& p = impl_->photons[idx[m]];
    if (glm::dot(p.normal(), n) < 0.5f) continue;  // other side or another surface
    ph[used] = &p;
    dd[used] = d2[m];
    ++used;
  }
  if (used == 0) return glm::vec3(0.f);
  float r2 = dd[used - 1];
  if (used < k) {
    // Fewer than k on this side: the density of the whole disk examined —
    // the gather radius if the search ended inside it, else the farthest candidate.
    r2 = found < want && r2max < HUGE_VALF ? r2max : d2[found - 1];
  }
  r2 = std::max(r2, impl_->surface.minRadius2());  // the ray offset's (photon_surface.h)
  const float r = std::sqrt(r2);
  constexpr float c = 1.1f;
  // The k-th photon on the disk's edge is left out, as in PhotonMap::irradiance
  // (photon_map.h): k / (pi r_k^2) is k / (k - 1) times the density.
  const int counted = used == k && k >= 2 ? used - 1 : used;
  glm::dvec3 sum(0.0);
  for (int m = 0; m < counted; ++m) sum += double(std::max(0.f, 1.f - std::sqrt(dd[m]) / (c * r))) * glm::dvec3(ph[m]->power);
  double area = impl_->surface.coneArea(x, n, r, c);
  // The hit's own faces hold it; no area only for a point off every counted face.
  if (!(area > 0.0)) area = M_PI * double(r2) * (1.0 - 2.0 / (3.0 * c));
  return glm::vec3(sum / area);
}

}  // namespace gi::eye

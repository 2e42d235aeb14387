// Parameters that make a photon-mapping result meaningless, said in the log.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

#include "photon_internal.h"

namespace gi {

namespace {

std::string num(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.3g", v);
  return buf;
}

}  // namespace

std::optional<std::string> smallKWarning(const std::string& name, int k) {
  // k Phi / A(r_k): A(r_k) / lambda is Gamma(k)-distributed, so the
  // estimate's mean (k / (k - 1)) is infinite at k = 1, its variance at k = 2.
  if (k > 2) return std::nullopt;
  return name + " = " + std::to_string(k) + ": the k-nearest estimate k Phi / (pi r_k^2) has " +
         (k == 1 ? "no finite mean" : "no finite variance") + " (r_k is random); use k >= 16";
}

void warnMeaninglessPhotonParameters(const PhotonOptions& opt, const PhotonGatherCheck& c, double unit, RunStats& st) {
  // The mean distance between photons, sqrt(area / photons): a radius below
  // it holds about pi (r / spacing)^2 < pi photons, mostly 0 or 1.
  bool capTooSmall = false;
  if (opt.maxRadius > 0.0 && c.mapPhotons > 0 && c.surfaceArea > 0.0) {
    const double spacing = std::sqrt(c.surfaceArea / double(c.mapPhotons));
    if (opt.maxRadius < spacing) {
      capTooSmall = true;
      // Lengths and areas in the mesh's own units (the options here are local: Scene::unit).
      st.warn("max_radius " + num(opt.maxRadius * unit) + " is below the mean photon spacing " + num(spacing * unit) +
              " (sqrt of " + num(c.surfaceArea * unit * unit) + " diffuse area / " + std::to_string(c.mapPhotons) +
              " photons): a gather holds 0 or 1 photon, read as the density of its whole disk, so vertex values are 0 or "
              "many times too bright; use max_radius >= " + num(spacing * std::sqrt(opt.kNearest / M_PI) * unit) + " (room for " +
              std::to_string(opt.kNearest) + " photons) or more photons");
    }
  }
  if (!capTooSmall && c.estimates > 0 && c.fewEstimates * 10 > c.estimates)
    st.warn(std::to_string(c.fewEstimates) + " of " + std::to_string(c.estimates) + " density estimates hold fewer than " +
            std::to_string(kFewPhotons) + " photons (relative noise above 50%): raise max_radius or the photon count");
  // No photon where surfaces reflect: every photon path ended before the map
  // kept one (with the direct light sampled, the map keeps only photons
  // after a bounce), and the result is the direct light alone with no more
  // than a note (an outside audit: photons 1 left a closed room 23% dark).
  // From many paths an empty map says that no light reaches a second
  // surface after a diffuse reflection (a plane under the sky): nothing is
  // missing, and the warning said it was (an outside audit); from few, the
  // light may be there and unsampled.
  constexpr int kManyPaths = 10000;
  if (c.mapPhotons == 0 && c.reflects && opt.photons < kManyPaths)
    st.warn("the photon map holds no photons (" + std::to_string(opt.photons) +
            " photon paths): the light beyond the direct light is missing; shoot more photons");
  else if (c.mapPhotons == 0 && c.reflects)
    st.note("the photon map holds no photons from " + std::to_string(opt.photons) +
            " photon paths: no light reaches another surface after a diffuse reflection (an open scene); the result "
            "is the direct light");
  if (c.kNearestEstimates) {
    auto kCheck = [&](const char* name, int k, size_t photons, const char* map) {
      if (const auto w = smallKWarning(name, k))
        st.warn(*w);
      else if (photons > 0 && photons < size_t(k))
        st.warn(std::string(name) + " " + std::to_string(k) + " exceeds the " + std::to_string(photons) + " photons of the " +
                map + ": every estimate spans them all (one blurred average); shoot more photons");
    };
    kCheck("k_nearest", opt.kNearest, c.mapPhotons, "global map");
    if (c.causticPhotons > 0) kCheck("caustic_k", opt.causticK, c.causticPhotons, "caustic map");
  }
  // 1%: at rho 0.9 the default 32 bounces lose 2.3% of the power, and a
  // room's half lit only through gaps read 4.7% dark (an outside check). The
  // share is the channel's that loses most: in a closed room each channel's
  // radiosity misses what that channel's cut paths carried, and a colour
  // that reflects more dominates the result's luminance (a furnace of sRGB
  // reflectance 250, 188, 100 at 32 bounces: 5.1% of the luminance power,
  // 21% of the red, the result 16.5% dark; an outside audit).
  const double share = std::max(c.lostPowerFraction, c.lostChannelShare);
  if (share > 0.01) {
    static const char* const kChannel[3] = {"red", "green", "blue"};
    st.warn("paths cut at max_depth " + std::to_string(opt.maxDepth) + " still carried " + num(100.0 * share) + "% of the " +
            (c.lostChannelShare >= c.lostPowerFraction ? std::string(kChannel[c.lostChannel]) + " " : std::string()) +
            "emitted power (" + num(100.0 * c.lostPowerFraction) +
            "% of its luminance): the result is too dark by up to that; raise max_depth");
  }
}

}  // namespace gi

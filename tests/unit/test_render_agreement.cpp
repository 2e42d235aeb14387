// The two-pass renderer against the path-traced yardstick on the shipped
// scenes: the Cornell box (first pass: radiosity) and the caustic Cornell
// box (glass sphere and mirror; first pass: photon mapping, caustics read
// from the eye pass's own caustic map). Same camera (the filter's default
// framing), same image.
//
// The measure: the image cut into 16 x 16-pixel tiles; in each tile the mean
// luminance of the two images. The path tracer's error bar per tile is
// sqrt(sum of its pixels' squared standard errors) / 256 (independent
// pixels); the two-pass image's spread is its QMC samples' (an upper bound,
// added likewise). Each tile must agree within 4 of these combined errors
// plus a stated share of the path-traced tile for the first pass's own bias
// (what the first pass computes at the vertices and the eye pass
// interpolates: radiosity's discretisation and photon mapping's density
// estimates), and the whole image within 4 errors plus a smaller share.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "gi/color.h"
#include "gi/photon.h"
#include "gi/radiosity.h"
#include "gi/render.h"
#include "gi/scenes.h"
#include "render_test_helpers.h"

using namespace gi;
using gi::test::BlockSums;
using gi::test::blockSums;

namespace {

Camera framing(const Scene& s, int w, int h) {
  glm::dvec3 lo(std::numeric_limits<double>::infinity()), hi(-std::numeric_limits<double>::infinity());
  for (const auto& p : s.positions) {
    lo = glm::min(lo, s.toWorld(p));
    hi = glm::max(hi, s.toWorld(p));
  }
  return Camera::frame(lo, hi, {0, 0, 1}, {0, 1, 0}, 39.3, w, h);
}

struct Agreement {
  double worstTileExcess = 0;  // max over tiles of |a - b| / (4 sigma + share b) (<= 1 passes)
  double wholeA = 0, wholeB = 0, wholeSigma = 0;
  double lowest = 0, highest = 0;  // tile differences (a - b) / b
  int tiles = 0;
};

Agreement compareTiles(const RenderResult& tp, const RenderResult& pt, double share) {
  const int W = tp.image.width, H = tp.image.height, T = 16;
  Agreement g;
  double va = 0, vb = 0;
  for (int by = 0; by + T <= H; by += T)
    for (int bx = 0; bx + T <= W; bx += T) {
      const BlockSums s = blockSums(tp, pt, bx, by, T);
      const double a = s.a, b = s.b, sa = s.varA, sb = s.varB;
      const double n = double(T) * T;
      const double sigma = std::sqrt(sa + sb) / n;
      const double excess = std::abs(a - b) / n / (4 * sigma + share * b / n + 1e-9);
      g.worstTileExcess = std::max(g.worstTileExcess, excess);
      g.lowest = std::min(g.lowest, (a - b) / b);
      g.highest = std::max(g.highest, (a - b) / b);
      g.wholeA += a;
      g.wholeB += b;
      va += sa;
      vb += sb;
      ++g.tiles;
    }
  const double n = double(g.tiles) * T * T;
  g.wholeA /= n;
  g.wholeB /= n;
  g.wholeSigma = std::sqrt(va + vb) / n;
  return g;
}

}  // namespace

// Radiosity (1,024 form-factor rays per patch, vertices by final gather)
// as the first pass; two-pass with ray-traced direct light + the stored
// indirect part. Share 4%: measured tile differences -2.9% .. +0.2% (sigma
// 0.3-2.6%), largest at the floor's front edge where the interpolated
// indirect part rounds off the corner; whole image -0.5%, allowed 1.5%. An
// indirect part 15% too bright fails (tiles up to +10%).
TEST(RenderAgreement, CornellBoxTwoPassMatchesPathTraced) {
  const Scene s = scenes::cornellBox(50.0).scene;
  auto caster = makeEmbreeCaster(s);
  RadiosityOptions ro;
  const RadiosityResult first = solveRadiosity(s, *caster, ro);
  RenderOptions o;
  o.camera = framing(s, 64, 64);
  o.mode = RenderMode::TwoPass;
  o.twoPass = TwoPassDiffuse::DirectIndirect;
  o.samplesPerPixel = 16;
  o.firstPassB = first.Bvertex;
  const RenderResult tp = render(s, *caster, o);
  o.mode = RenderMode::PathTraced;
  o.samplesPerPixel = 1024;
  const RenderResult pt = render(s, *caster, o);
  const Agreement g = compareTiles(tp, pt, 0.04);
  EXPECT_EQ(g.tiles, 16);
  EXPECT_LE(g.worstTileExcess, 1.0);
  EXPECT_NEAR(g.wholeA, g.wholeB, 4 * g.wholeSigma + 0.015 * g.wholeB) << "sigma " << g.wholeSigma;
}

// Photon mapping (default settings, 400k photons) as the first pass;
// two-pass with ray-traced direct light, the caustic map read at each hit
// (the first pass's own caustics taken out of its indirect part: the same
// photons and k) and the stored indirect part. Share 6%: photon mapping's
// density estimates blur the indirect light; measured tile differences
// -4.2% .. +3.0% (sigma 0.5-2.8%), whole image +0.01%, allowed 2%.
TEST(RenderAgreement, CausticCornellBoxTwoPassMatchesPathTraced) {
  const Scene s = scenes::causticCornell(50.0, 10.0, 5, 1.5f);
  auto caster = makeEmbreeCaster(s);
  PhotonOptions po;
  po.photons = 400000;
  const VertexRadiometry first = computePhotonMap(s, *caster, po);
  RenderOptions o;
  o.camera = framing(s, 64, 64);
  o.mode = RenderMode::TwoPass;
  o.twoPass = TwoPassDiffuse::Caustics;
  o.samplesPerPixel = 16;
  o.causticPhotons = po.photons;
  o.causticK = po.causticK;
  o.firstPassB = first.B;
  o.firstPassBdirect = first.Bdirect;  // as the filter passes it on (the attribute RadiosityDirect)
  const RenderResult tp = render(s, *caster, o);
  o.mode = RenderMode::PathTraced;
  o.samplesPerPixel = 1024;
  const RenderResult pt = render(s, *caster, o);
  const Agreement g = compareTiles(tp, pt, 0.06);
  EXPECT_EQ(g.tiles, 16);
  EXPECT_LE(g.worstTileExcess, 1.0);
  EXPECT_NEAR(g.wholeA, g.wholeB, 4 * g.wholeSigma + 0.02 * g.wholeB) << "sigma " << g.wholeSigma;
  // The final gather (16 rays per eye-ray hit) reads the same first pass
  // where its rays land: the vertices' blur is averaged over the hemisphere
  // instead of seen directly. Share 3%: measured tile differences -1.8% ..
  // +2.3% (sigma as above), whole image -0.09%, allowed 1%. A gather 15%
  // too bright fails (tiles up to +12%).
  o.mode = RenderMode::TwoPass;
  o.twoPass = TwoPassDiffuse::FinalGather;
  o.samplesPerPixel = 16;
  const Agreement gg = compareTiles(render(s, *caster, o), pt, 0.03);
  EXPECT_EQ(gg.tiles, 16);
  EXPECT_LE(gg.worstTileExcess, 1.0) << "tiles " << gg.lowest << " .. " << gg.highest;
  EXPECT_NEAR(gg.wholeA, gg.wholeB, 4 * gg.wholeSigma + 0.01 * gg.wholeB) << "sigma " << gg.wholeSigma;
}

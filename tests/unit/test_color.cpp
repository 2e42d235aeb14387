// gi/color.h: sRGB both ways, luminance, the display mapping and auto
// exposure. All inputs are exact and small: every check is deterministic.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <vector>

#include "gi/color.h"

namespace {

constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();
constexpr float kInf = std::numeric_limits<float>::infinity();

// ---------------------------------------------------------------- color ----

TEST(Color, SrgbRoundTripAllBytes) {
  // All 256 byte values decode and re-encode to themselves (lround); linear
  // values increase strictly; srgb8ToLinear is the per-channel decode.
  float prev = -1.f;
  for (int b = 0; b < 256; ++b) {
    const float lin = gi::srgbToLinear(b / 255.f);
    EXPECT_GT(lin, prev) << b;
    prev = lin;
    EXPECT_EQ(std::lround(gi::linearToSrgb(lin) * 255.f), b);
    const glm::vec3 c = gi::srgb8ToLinear(uint8_t(b), 0, 255);
    EXPECT_EQ(c.r, lin);
    EXPECT_EQ(c.g, 0.f);
    EXPECT_FLOAT_EQ(c.b, 1.f);
  }
  // Reference points of IEC 61966-2-1; tolerance 1e-5.
  EXPECT_NEAR(gi::srgbToLinear(0.5f), 0.214041f, 1e-5f);
  EXPECT_NEAR(gi::linearToSrgb(0.18f), 0.461356f, 1e-5f);
  EXPECT_NEAR(gi::linearToSrgb(0.0031308f), 0.04045f, 1e-5f);  // both branches meet
  EXPECT_EQ(gi::linearToSrgb(-1.f), 0.f);
  EXPECT_FLOAT_EQ(gi::linearToSrgb(2.f), 1.f);  // 1.055 - 0.055 in float: within 4 ulps
}

TEST(Color, LuminanceWeights) {
  // Rec. 709: exact weights (float), summing to 1 within 1e-6.
  EXPECT_FLOAT_EQ(gi::luminance({1, 0, 0}), 0.2126f);
  EXPECT_FLOAT_EQ(gi::luminance({0, 1, 0}), 0.7152f);
  EXPECT_FLOAT_EQ(gi::luminance({0, 0, 1}), 0.0722f);
  EXPECT_NEAR(gi::luminance({1, 1, 1}), 1.f, 1e-6f);
  EXPECT_NEAR(gi::luminance({2, 4, 8}), 2 * 0.2126f + 4 * 0.7152f + 8 * 0.0722f, 1e-5f);
}

TEST(Color, DisplayMap) {
  auto eq = [](gi::Rgb8 a, int r, int g, int b) { return a.r == r && a.g == g && a.b == b; };
  EXPECT_TRUE(eq(gi::displayMap({0, 0, 0}, 1.f), 0, 0, 0));
  EXPECT_TRUE(eq(gi::displayMap({1, 1, 1}, 1.f), 255, 255, 255));
  EXPECT_TRUE(eq(gi::displayMap({0.25f, 0.25f, 0.25f}, 2.f), 188, 188, 188));  // exposure 2: 0.5 -> 188
  EXPECT_TRUE(eq(gi::displayMap({1e6f, 0, 0}, 1.f), 255, 0, 0));
  EXPECT_TRUE(eq(gi::displayMap({-1, -0.5f, 0}, 1.f), 0, 0, 0));
  // Over-bright: scaled by the largest channel (hue kept) rather than clipped
  // per channel: (4, 2, 1) -> (1, 0.5, 0.25) -> sRGB (255, 188, 137).
  const gi::Rgb8 c = gi::displayMap({4.f, 2.f, 1.f}, 1.f);
  EXPECT_TRUE(eq(c, 255, 188, 137)) << int(c.r) << "," << int(c.g) << "," << int(c.b);
  // Decoded ratios of the bytes stay 2:1 within the 8-bit quantisation (1%).
  const glm::vec3 lin = gi::srgb8ToLinear(c.r, c.g, c.b);
  EXPECT_NEAR(lin.r / lin.g, 2.f, 0.02f);
  EXPECT_NEAR(lin.g / lin.b, 2.f, 0.02f);
  // NaN: black (per channel).
  EXPECT_TRUE(eq(gi::displayMap({kNaN, kNaN, kNaN}, 1.f), 0, 0, 0));
  const gi::Rgb8 n = gi::displayMap({kNaN, 1.f, 0.f}, 1.f);
  EXPECT_EQ(n.r, 0);
  EXPECT_EQ(n.g, 255);
  EXPECT_TRUE(eq(gi::displayMap({1.f, 1.f, 1.f}, kNaN), 0, 0, 0));
}

TEST(Color, AutoExposureIgnoresNaNAndZero) {
  // 1..100: the 0.99 percentile (rank round(0.99 * 99) = 98) is 99.
  std::vector<float> v;
  for (int i = 1; i <= 100; ++i) v.push_back(float(i));
  const float e = gi::autoExposure(v.data(), v.size());
  EXPECT_FLOAT_EQ(e, 1.f / 99.f);
  std::vector<float> dirty = v;
  for (int k = 0; k < 50; ++k) {
    dirty.insert(dirty.begin() + 2 * k, kNaN);
    dirty.push_back(0.f);
    dirty.push_back(-3.f);
  }
  dirty.push_back(kInf);
  EXPECT_FLOAT_EQ(gi::autoExposure(dirty.data(), dirty.size()), e);
  const float zeros[4] = {0.f, 0.f, kNaN, -1.f};
  EXPECT_EQ(gi::autoExposure(zeros, 4), 1.f);
  EXPECT_EQ(gi::autoExposure(nullptr, 0), 1.f);
  const float one[1] = {4.f};
  EXPECT_FLOAT_EQ(gi::autoExposure(one, 1), 0.25f);
  EXPECT_FLOAT_EQ(gi::autoExposure(v.data(), v.size(), 0.5f), 1.f / 51.f);  // rank round(49.5) = 50
}

}  // namespace

// Colour conventions shared by all filters (docs/design.md, "Conventions").
#pragma once
#include <cstdint>
#include <glm/glm.hpp>

namespace gi {

// sRGB transfer function (IEC 61966-2-1), per channel in [0,1].
float srgbToLinear(float c);
float linearToSrgb(float c);
glm::vec3 srgb8ToLinear(uint8_t r, uint8_t g, uint8_t b);
// Rec. 709 luminance of linear RGB.
inline float luminance(const glm::vec3& c) { return 0.2126f * c.r + 0.7152f * c.g + 0.0722f * c.b; }
// The same weights in double, for sums that need them so (dot(w, c)).
inline const glm::dvec3 kLuminanceWeights{0.2126, 0.7152, 0.0722};

// Display mapping of a linear value: v * exposure, clamped to [0,1] channel-wise
// after scaling down so that the largest channel is 1 (hue kept), then sRGB.
struct Rgb8 { uint8_t r, g, b; };
Rgb8 displayMap(const glm::vec3& linear, float exposure);
// Auto exposure: maps the given percentile (0.99) of the luminances to 1.
float autoExposure(const float* lum, size_t n, float percentile = 0.99f);

}  // namespace gi

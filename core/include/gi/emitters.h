// Sampling points on area emitters in proportion to their emitted power,
// shared by direct lighting and photon emission.
#pragma once
#include <vector>

#include <glm/glm.hpp>

#include "gi/scene.h"

namespace gi {

class EmitterSampler {
 public:
  explicit EmitterSampler(const Scene& s);
  bool empty() const { return faces_.empty(); }
  double totalPower() const { return total_; }  // sum of luminance(E) * area, W
  struct Sample {
    glm::vec3 p, n;   // point and unit normal (emitting side)
    glm::vec3 E;      // emitted radiosity of the face (RGB, W/m^2)
    float pdfArea;    // probability density per unit area of this point
    uint32_t face;
  };
  // u in [0,1)^2: u.x picks the face (power CDF) and is reused, rescaled, for the point.
  Sample sample(glm::vec2 u) const;
  size_t faceCount() const { return faces_.size(); }

 private:
  const Scene& s_;
  std::vector<uint32_t> faces_;
  std::vector<double> cdf_;
  std::vector<float> area_;
  double total_ = 0.0;
};

}  // namespace gi

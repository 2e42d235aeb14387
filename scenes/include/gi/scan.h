// Generated "scans" for the ambient-occlusion benchmark: a base mesh refined
// by Loop subdivision (Loop 1987, "Smooth Subdivision Surfaces Based on
// Triangles") and displaced along its normals by band-limited noise, so that
// one object exists at any vertex count (4^levels times the base's faces)
// with the same fine detail: like one object scanned at rising resolution.
//   x' = x + A D sum_k 2^-k g(2^k f x / D) n(x),  k = 0..octaves-1
// with D the base's bounding-box diagonal, g gradient noise in [-1, 1]
// (Perlin 2002, "Improving Noise", hashed gradients), n the angle-weighted
// vertex normal of the subdivided surface.
#pragma once
#include "gi/scene.h"

namespace gi::scenes {

struct ScanOptions {
  int levels = 3;          // Loop subdivision steps (faces x 4 each)
  double amplitude = 0.006;  // A: of the diagonal, first octave
  double frequency = 12.0;   // f: first octave's cycles per diagonal
  int octaves = 3;
  uint32_t seed = 1;
};

// Loop subdivision, `levels` times. Boundary and non-manifold edges are
// creases (cubic B-spline rules along them).
Scene loopSubdivide(const Scene& base, int levels);
// The subdivided and displaced mesh (in the base's coordinates).
Scene displacedScan(const Scene& base, const ScanOptions& o);

}  // namespace gi::scenes

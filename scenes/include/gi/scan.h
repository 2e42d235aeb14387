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
#include <cstddef>

#include "gi/scene.h"
#include "gi/scenes.h"

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

// A scan in a room, for radiosity at scale: the base displaced as above
// (o.levels ignored: the largest count of Loop steps whose scan keeps at
// most kScanRoomScanShare of `triangles`), scaled to a largest extent of 1,
// standing 1e-3 above the floor at the centre of a closed room x, z in
// [-1.5, 1.5], y (up) in [0, 2.5] whose walls, floor and ceiling take the
// other triangles (roughly square patches of two). A 0.8 x 0.8 ceiling
// light (at most 200 triangles, 1e-3 below a hole of its size in the
// ceiling, facing down, emission 1: face quality 1) sits above the scan
// towards z < 0; the wall
// x = 1.5 has a window opening (z in [-0.6, 0.6], y in [0.8, 1.8]) for sky
// light (the filters' sky parameters). Reflectances: scan 0.6, floor 0.4,
// walls and ceiling 0.75. The scan's triangles come first, keeping its
// winding; the room's face inwards. About `triangles` in all (the room's
// patches are rounded per rectangle); deterministic for a base and seed.
inline constexpr double kScanRoomScanShare = 0.9;
SceneFile scanRoom(const Scene& base, size_t triangles, const ScanOptions& o);

}  // namespace gi::scenes

// The hemicube of one patch made visible (Cohen and Greenberg 1985, "The
// Hemi-Cube: A Radiosity Solution for Complex Environments"), and Nusselt's
// analogue beside it (Nusselt 1928; Cohen and Wallace 1993, "Radiosity and
// Realistic Image Synthesis", ch. 4):
//  - the five faces of the hemicube at the patch's centre, unfolded into a
//    cross (the top face in the middle, each side folded out around it),
//    every cell coloured by the patch it shows; and the same cells coloured
//    by their delta form factor
//      top:  dF = h^2 / (pi (x^2 + y^2 + 1)^2),  side: dF = y h^2 / (pi (x^2 + y^2 + 1)^2),
//    so that F_ij = sum of the cells showing j (normalised by the sum of all);
//  - the Nusselt analogue: patch j projected onto the unit hemisphere
//    around the point, then straight down onto the hemisphere's base disk;
//    the area it covers there, divided by pi, is the point's form factor
//      F_dA->j = A_disk(j) / pi.
//    Seen from above, the disk is drawn by a ray from the point through
//    each pixel's place on the hemisphere, so it does not depend on the
//    hemicube: the two pictures are two methods to compare.
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include "gi/color.h"
#include "gi/form_factors.h"
#include "gi/image.h"
#include "gi/params.h"
#include "gi/raycaster.h"
#include "gi/scene.h"

namespace gi {

struct HemicubeView {
  HemicubeCells cells;  // the hemicube method's one central view (hemicube_points = 1)
  Image byPatch;        // unfolded cross, 2 res x 2 res: cell colour = patchColor(patch)
  Image deltaF;         // the same cells by dF / (h^2 / pi) on a ramp (1 at the top's centre)
  Image nusselt;        // the base disk, nusseltResolution pixels across, by patch
  int nusseltResolution = 0;
  std::vector<uint32_t> nusseltPatch;  // per disk pixel: the patch seen, kNoHit (nothing, a back, outside)
  std::vector<double> nusseltF;        // per face of the scene: covered disk area / pi
  double nusseltLost = 0;              // disk area / pi seeing nothing or a back
};

// The hemicube (resolution cells across the top) and the Nusselt disk of
// `face`, seen from the point the hemicube method uses (the centroid, lifted
// by the ray epsilon). Throws std::invalid_argument for a missing or
// degenerate face.
HemicubeView hemicubeView(const Scene& s, const RayCaster& caster, uint32_t face, int resolution,
                          int nusseltResolution);

// A stable colour per patch id (sRGB bytes; the same in every picture and on
// the mesh's faces): hue, saturation and value hashed from the id.
Rgb8 patchColor(uint32_t id);
// The colours the pictures use where a cell shows no patch.
inline constexpr Rgb8 kSeesNothing{0, 0, 0}, kSeesBack{64, 64, 64}, kOutside{255, 255, 255};
// The ramp of the delta form factor picture, t in [0, 1].
glm::vec3 deltaFRamp(float t);

// The filter's parameters (after the scene extent): face, resolutions, image path.
std::vector<ParamSpec> hemicubeViewSpecs();

}  // namespace gi

// Canonical test scenes with analytic references (docs/design.md, "Analytic references"), built in
// double precision. Every triangle is counter-clockwise seen from its front
// (the side light reflects from); walls are split into roughly square patches
// of two triangles each.
#pragma once
#include <string>
#include <vector>

#include "gi/scene.h"
#include "gi/scene_setup.h"

namespace gi::scenes {

// A scene and the same data as mesh attributes, so it can be written to PLY:
// faceColor = sRGB bytes of rho, faceQuality = 1 for emitters, 0 otherwise.
struct SceneFile {
  Scene scene;            // rho (linear) and emission set per face
  MeshAttributes attrs;
};

// Cornell box, published geometry in millimetres (camera side z = 0 open).
// Light 130 x 105 mm at y = 548.7 facing down, E = pi * (17, 12, 4) W/m^2.
SceneFile cornellBox(double patchSize);
// Two coaxial unit squares at distance L facing each other, n x n patches each.
// The one at z = 0 emits E = 1; rho = 0 everywhere (irradiance = form factor).
SceneFile parallelPlates(double L, int n);
// Unit squares in z = 0 (emitting, E = 1) and x = 0 sharing the edge along y,
// both facing into the quadrant x, z > 0; rho = 0.
SceneFile perpendicularPlates(int n);
// Icosphere of 20 * 4^subdivisions faces centred at 0, rho 0.5, no emission.
SceneFile sphere(double radius, int subdivisions, bool inward);
// Cube [-size/2, size/2]^3, n x n patches per side, rho 0.5.
SceneFile closedBox(double size, int n, bool inward);
// Square [-size/2, size/2]^2 in z = 0 facing +z.
SceneFile openPlane(double size, int n);
// Floor z = 0 (x in [0, floorSize]) facing +z and wall x = 0 (z in [0, wallHeight])
// facing +x, both max(floorSize, 20 * wallHeight) wide in y (about infinite).
// Patch edge floorSize / n.
SceneFile floorWithWall(double floorSize, double wallHeight, int n);
// Inside of the lower hemisphere of radius r centred at 0 (rim at z = 0), normals
// towards the centre, a vertex at (0, 0, -radius); n rings from bottom to rim.
SceneFile hemisphericalBowl(double radius, int n);
// Ground z = 0 from radius a to 10 a, cylinder wall of radius a down to z = -h,
// bottom disk with a vertex at (0, 0, -h); faces towards the open space.
// Patch edge a / n.
SceneFile cylindricalHole(double a, double h, int n);

// The caustic Cornell box: the box without its blocks (floor patches of
// floorPatch), a glass sphere (radius 80 mm, centre kGlassCentre, icosphere
// of 20 * 4^sphereSubdiv faces) and a mirror on the back wall (x 330..500,
// y 30..250, z = 558.7, facing the room). Three layers, named as MeshLab would
// name the shipped files: caustic_cornell_{box,glass_sphere,mirror}.ply.
struct NamedLayer {
  std::string name;
  SceneFile file;
};
std::vector<NamedLayer> causticCornellLayers(double patchSize, double floorPatch, int sphereSubdiv);
inline const glm::dvec3 kGlassCentre{185.0, 180.0, 200.0};
inline constexpr double kGlassRadius = 80.0;
// The layers in one scene with the materials applied (mirror_layers
// '*mirror*', glass_layers '*glass*', the given index of refraction).
Scene causticCornell(double patchSize, double floorPatch, int sphereSubdiv, float ior);

// A glossy block standing on the caustic Cornell box's floor, right of
// centre in front of the mirror (its reflection and the mirror stay in the
// framing camera's view): a square of side 2 kGlossyHalfWidth turned by
// kGlossyTurnDeg about the vertical (its faces reflect the coloured walls),
// kGlossyHeight high, no bottom face; patches of about `patch`.
inline const glm::dvec3 kGlossyCentre{415.0, 0.0, 175.0};
inline constexpr double kGlossyHalfWidth = 50.0, kGlossyHeight = 85.0, kGlossyTurnDeg = 35.0;
SceneFile glossyBlock(double patch);
// The caustic Cornell box's layers and the glossy block's,
// caustic_cornell_glossy_block.ply (a glossy layer by its name: *glossy*).
std::vector<NamedLayer> causticCornellGlossyLayers(double patchSize, double floorPatch, int sphereSubdiv);
// Those layers in one scene, the block Glossy with GGX roughness alpha and
// specular colour F0 (linear).
Scene causticCornellGlossy(double patchSize, double floorPatch, int sphereSubdiv, float ior, float roughness,
                           const glm::vec3& F0);

// Meshing artefacts (the course's "shadow leak" and "staircase"), z up:
//
// Shadow leak: a closed room x in [0, 2], y in [0, 1.2], z in [0, 1] seen
// from inside, coarse patches (0.4 along x), rho 0.5, split by a partition
// (two faces, x = 1.09 facing -x and x = 1.11 facing +x, reaching 1 cm into
// floor, ceiling and walls) that cuts through the floor, ceiling and side
// wall patches spanning x in [0.8, 1.2] (their triangles' centroids lie on
// the lit side); a light 0.4 x 0.4 (black, emitting) 2 cm below the ceiling
// over the lit half. No light reaches the dark half: B = 0 for x > 1.11.
SceneFile shadowLeak();
// Staircase: floor [-1, 1]^2 at z = 0 (rho 0.5, 8 x 8 quads), a light
// kStaircaseLight wide (black, emitting) at z = 2 facing down, centred over
// the origin, and a black occluder at z = 1 whose edge, turned 30 degrees
// from the y axis, passes over (0.2, 0, 1): a nearly hard shadow edge through
// (0.4, 0, 0) running diagonally across the patches. The floor sees only black
// surfaces, so B_floor = rho H_direct exactly.
inline constexpr double kStaircaseLight = 0.05;
SceneFile staircase();

// Sets uniform reflectance and emission on every face (and the attributes).
void setUniform(SceneFile& sf, const glm::vec3& rho, const glm::vec3& E);

// Names accepted by byName, each with default parameters.
std::vector<std::string> names();
// Throws std::invalid_argument for an unknown name.
SceneFile byName(const std::string& name);
// Scenes of several layers (files) by name, e.g. "caustic_cornell"; a
// one-layer scene for the other names (layer name NAME.ply).
std::vector<NamedLayer> layersByName(const std::string& name);

}  // namespace gi::scenes

// The engine's scene: triangles with per-face materials. No Qt, no MeshLab.
#pragma once
#include <cmath>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <glm/glm.hpp>

namespace gi {

// Glossy: the GGX microfacet reflector of gi/glossy.h (roughness per face,
// specular colour in rho), shaded by the ray tracer, photon mapping and the
// reference; like mirrors and glass it carries no diffuse radiosity.
enum class Material : uint8_t { Diffuse = 0, Mirror = 1, Glass = 2, Glossy = 3 };

// Positions are stored relative to `origin` (double), so that meshes far from
// the coordinate origin (offsets of 1e6) keep full float precision in the
// ray caster, and in units of `unit` (a world length), so that a scene 1e-20
// or 1e38 across computes like one of ordinary size: squared distances,
// areas and ray offsets of such scenes underflow or overflow a float (NaN
// rays, light escaping closed boxes). Algorithms work in these local units;
// parameters they take in world units (distances, a point light's position
// and intensity) are converted on entry (the *InLocalUnits helpers), and
// results per area (irradiance, radiosity, exitance) need no conversion. Use
// Scene::fromAbsolute to fill it from absolute coordinates.
struct Scene {
  glm::dvec3 origin{0.0};
  double unit = 1.0;                      // world length of one local unit (1 or a power of two)
  std::vector<glm::vec3> positions;       // relative to origin
  std::vector<glm::uvec3> triangles;      // vertex indices, counter-clockwise = front
  std::vector<glm::vec3> vertexNormals;   // optional (empty: computed from faces)
  std::vector<glm::vec3> rho;             // per-face linear RGB reflectance (empty: 0.5 grey)
  std::vector<glm::vec3> emission;        // per-face emitted radiosity E, W/m^2 (empty: none)
  std::vector<Material> material;         // per face (empty: all diffuse)
  std::vector<float> ior;                 // per face index of refraction for Glass (empty: 1.5)
  std::vector<float> roughness;           // per face GGX alpha for Glossy (empty: 0.2)
  // Per face (empty: none): faces every computation leaves out, as it does a
  // degenerate one (the filters' set-up marks a duplicated face's copies).
  std::vector<uint8_t> leftOut;

  size_t vertexCount() const { return positions.size(); }
  size_t faceCount() const { return triangles.size(); }
  glm::vec3 faceRho(size_t f) const { return rho.empty() ? glm::vec3(0.5f) : rho[f]; }
  glm::vec3 faceEmission(size_t f) const { return emission.empty() ? glm::vec3(0.f) : emission[f]; }
  Material faceMaterial(size_t f) const { return material.empty() ? Material::Diffuse : material[f]; }
  float faceRoughness(size_t f) const { return roughness.empty() ? 0.2f : roughness[f]; }
  bool hasEmitters() const;

  // Absolute <-> local coordinates.
  glm::dvec3 toWorld(const glm::vec3& p) const { return origin + unit * glm::dvec3(p); }
  // Re-centres a scene given in absolute double coordinates, in the local
  // unit unitFor(its bbox diagonal).
  static Scene fromAbsolute(const std::vector<glm::dvec3>& pts, std::vector<glm::uvec3> tris);
  // Appends another scene (its vertices re-expressed relative to this origin
  // and, if the union's size asks for another unit, all of them rescaled).
  // Returns the vertex offset of the appended part.
  size_t append(const Scene& other);
  // The local unit for a scene of this world diagonal: 1 from 2^-10 to 2^20
  // (about 1e-3 to 1e6: every scene of ordinary size keeps its numbers bit
  // for bit), else the power of two at or below it, so that local positions
  // lie within [-1, 1] and scaling by it is exact.
  static double unitFor(double diagonal);
};

// FNV-1a hash of what a lighting result depends on: absolute positions,
// triangles, reflectance, emission and materials. Keys cached references.
uint64_t sceneHash(const Scene& s);

// Geometry helpers (local coordinates).
glm::vec3 faceNormalUnnormalized(const Scene& s, size_t f);  // cross product, |n| = 2 * area
double faceArea(const Scene& s, size_t f);
// Unit face normals (winding order); +z for degenerate faces.
std::vector<glm::vec3> unitFaceNormals(const Scene& s);
// Angle-weighted vertex normals from the faces; zero vector for isolated
// vertices. `usable`: usableFaceMask(s), where the caller already has it (a
// pass over every face less; computed here otherwise). The same below.
std::vector<glm::vec3> computeVertexNormals(const Scene& s, const std::vector<uint8_t>* usable = nullptr);
// The vertex normals every per-vertex estimator uses: s.vertexNormals if it
// has one per vertex (a library caller's own), each scaled to unit length in
// double (the estimators' frames, ray origins and open-vertex proofs assume
// it); where it is zero or not finite (an exporter's 0 0 0 for "none") the
// faces' normal as computeVertexNormals gives it; zero where the vertex is
// on no usable face, as a computed one would be (such a vertex then counts
// as invalid). Without s.vertexNormals: computeVertexNormals(s, usable).
std::vector<glm::vec3> vertexNormalsForRays(const Scene& s, const std::vector<uint8_t>* usable = nullptr);

struct SceneReport {
  size_t vertices = 0, faces = 0;
  size_t nonFiniteVertices = 0;    // NaN or Inf coordinates
  size_t invalidFaces = 0;         // index out of range or repeated index
  size_t degenerateFaces = 0;      // zero (or relatively tiny) area
  size_t facesOnNonFinite = 0;     // faces touching a non-finite vertex
  size_t isolatedVertices = 0;     // referenced by no usable face
  size_t emitterFaces = 0;
  size_t leftOutFaces = 0;         // Scene::leftOut (not counted as degenerate)
  size_t duplicateFaces = 0;       // usable faces repeating an earlier face's corners, in its turn
  size_t misorientedEdges = 0;     // edges of two faces that run along them the same way (one face turned over)
  size_t twoSidedPairs = 0;        // corners with faces of both turns (a two-sided surface's faces)
  // Edges (by position) that only one usable face has: 0 for a closed mesh
  // (counted with duplicateFaces; a T-junction counts as a border).
  size_t borderEdges = 0;
  double emittedPower = 0.0;       // luminance-weighted, W
  glm::dvec3 bboxMin{0.0}, bboxMax{0.0};  // absolute, over finite vertices
  double diagonal = 0.0;           // bbox diagonal of the vertices some face uses (world units)
  double rayEpsilon = 0.0;         // offset for ray origins (local units)
  size_t usableFaces() const { return faces - invalidFaces - degenerateFaces - facesOnNonFinite - leftOutFaces; }
  std::string summary() const;     // one line for logs
};

// Counts every defect and computes the scale used for ray offsets. Without
// duplicateFaces (left 0) it skips the one part that sorts every face
// (0.1 s at a million faces): for algorithms that do not depend on it.
// *duplicates (if given, with duplicateFaces): the pairs duplicatedFaces returns.
SceneReport analyzeScene(const Scene& s, bool duplicateFaces = true, const std::vector<uint8_t>* usable = nullptr,
                         std::vector<std::pair<uint32_t, uint32_t>>* duplicates = nullptr);
// The usable faces that repeat an earlier usable face's three corner
// positions in the same turn, each with that face: (copy, original) pairs,
// the original the first face of its group.
std::vector<std::pair<uint32_t, uint32_t>> duplicatedFaces(const Scene& s);
// Only the scale (one pass over the vertices): what the algorithms need for
// their ray offsets, without the defect counts of a full report.
// Everything that sizes a scene's geometry (a box framing it, a tolerance)
// takes these vertices only: one vertex no face uses, far away, made the
// shadow test take every face for one plane of a convex room (no shadow
// rays: 199 of the Cornell box's 1,010 vertices off by more than 20%), the
// sky's photons start on a disk around it (none stored) and a framed view
// look at nothing (an outside audit).
struct SceneScale {
  double diagonal = 0.0;    // bbox diagonal over the finite vertices some face uses (all if none; local units)
  double rayEpsilon = 0.0;  // offset for ray origins (local units)
  glm::dvec3 lo{0.0}, hi{0.0};  // their bounding box (local units; lo > hi where there are none)
  double maxAbs = 0.0;          // their largest coordinate in absolute value (local units)
};
SceneScale sceneScale(const Scene& s);
// The warning for absolute positions that are all floats with a float step
// at the largest coordinate above 1e-4 of their bounding box's diagonal
// (a mesh stored as floats far from the origin: its geometry already
// rounded), or none. The CLI's readers and MeshLab's bridge (whose meshes
// are floats) give it.
std::optional<std::string> coarseFloatsWarning(const std::vector<glm::dvec3>& pts);

// The bbox diagonal in world units (analyzeScene(s).diagonal without the rest of the analysis).
inline double sceneDiagonal(const Scene& s) { return sceneScale(s).diagonal * s.unit; }
// True for a face the ray caster builds (valid indices, finite, non-degenerate).
std::vector<uint8_t> usableFaceMask(const Scene& s);
// 1 for the vertices that only left-out faces use (a duplicated face's copy
// with corners of its own): no computation reaches them, and the output
// gives them their original's values, so they are neither isolated nor "got
// 0". Empty where no face is left out.
std::vector<uint8_t> copyOnlyVertices(const Scene& s);
// How many copy-only vertices satisfy pred(i): the count a "got 0" note
// leaves out, since those vertices show their originals' values.
template <class Pred>
size_t copyOnlyAmong(const Scene& s, Pred pred) {
  const std::vector<uint8_t> copies = copyOnlyVertices(s);
  size_t n = 0;
  for (size_t i = 0; i < copies.size(); ++i) n += copies[i] && pred(i);
  return n;
}
// Throws std::invalid_argument where a per-face array (rho, emission,
// material, ior, roughness, leftOut) is neither empty nor one entry per
// face: a library caller's mistake that would read past the array.
// usableFaceMask checks it, so every computation does.
void checkSceneArrays(const Scene& s);
// All three components finite (no NaN, no Inf).
inline bool finite3(const glm::vec3& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }
// The point of triangle (a, b, c) nearest to p (Ericson 2005, "Real-Time
// Collision Detection", 5.1.5: by the Voronoi regions of its corners and edges).
glm::dvec3 closestPointOnTriangle(const glm::dvec3& p, const glm::dvec3& a, const glm::dvec3& b, const glm::dvec3& c);
// For the functions that take the mask from a caller who already has it:
// *known if given, else usableFaceMask(s) computed into `own`.
const std::vector<uint8_t>& usableFaces(const Scene& s, const std::vector<uint8_t>* known, std::vector<uint8_t>& own);

}  // namespace gi

namespace gi {
// Ray origins for per-vertex estimators: lifted by eps along the normal and,
// where the one-ring is lopsided (mesh borders, the edge where a floor meets a
// separate wall sheet), pulled by 2 eps into the wedge its faces span (along
// the mean direction over the wedge, whatever its triangles), so that rays
// cannot slip under an adjacent wall at t = 0 and leak; never so far that
// the origin leaves the normal's side of one of its own faces.
std::vector<glm::vec3> vertexRayOrigins(const Scene& s, const std::vector<glm::vec3>& normals, float eps,
                                        const std::vector<uint8_t>* usable = nullptr);
// The point a vertex's lights are seen from (their distances and angles):
// its ray origin less the lift along the normal. That is the vertex itself,
// or at borders and creases the vertex pulled up to 2 eps into its faces'
// wedge, off the crease (a lamp whose plane meets the vertex would be seen
// edge-on from the crease itself). With the lift, a plane read eps / h low
// under a light at height h (an outside audit).
inline glm::vec3 vertexLightPoint(const glm::vec3& origin, const glm::vec3& normal, float eps) {
  return origin - eps * normal;
}
// Where a light whose plane passes through y (unit normal m) is seen from:
// the surface point x, unless x lies within 2 eps of that plane (a lamp's
// own plane through the vertex, the walls of a furnace meeting at its
// corner): there x would see it edge-on, and the lifted point `from` is
// used, as before 7 December 2026 (a light that close is within the
// offsets' bias anyway).
inline const glm::vec3& lightSeenFrom(const glm::vec3& x, const glm::vec3& from, const glm::vec3& y,
                                      const glm::vec3& m, float eps) {
  return std::fabs(glm::dot(m, x - y)) < 2.f * eps ? from : x;
}
}  // namespace gi

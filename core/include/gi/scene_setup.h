// The conventions (docs/design.md, "Conventions") in one place: how a mesh's colours, quality and
// selection become reflectance and emission, for the MeshLab bridge and the
// CLI alike; and how per-vertex results become quality and display colour.
#pragma once
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "gi/color.h"
#include "gi/emitters.h"
#include "gi/params.h"
#include "gi/scene.h"

namespace gi {

// What a mesh file or a MeshLab layer carries beside geometry (each optional).
struct MeshAttributes {
  std::vector<glm::u8vec3> faceColor;    // sRGB bytes
  std::vector<glm::u8vec3> vertexColor;  // sRGB bytes
  std::vector<float> faceQuality;
  std::vector<uint8_t> faceSelected;
  std::vector<uint8_t> vertexSelected;   // 1: selected (MeshLab's vertex selection, PLY vertex flags bit 0x20)
  // Not empty where the vertex colours display a result an earlier filter
  // left (its attribute's name, e.g. "Radiosity"): they are no reflectance,
  // and the reflectance source 'Auto' passes them over.
  std::string vertexColorShows;
  // Several layers are one scene: which faces' and vertices' colours a layer
  // gave (1) and which are the filler of a layer without them, or display
  // an earlier result in one layer (0). Empty: every colour present is
  // given (one mesh). The reflectance rule then holds per layer: a layer
  // without colours takes the constant, not the filler.
  std::vector<uint8_t> faceColorGiven, vertexColorGiven;
};

// The per-vertex attributes an earlier filter leaves, whose presence marks
// the vertex colours as a display of that result (radiosity, photon
// mapping, the reference, sky lighting, a view's vertex radiance; ambient
// occlusion, obscurance and thickness where they paint the colours: their
// greys were read as reflectance, AO's 0 inside a closed box as black
// walls; an outside audit).
inline constexpr const char* kResultAttributes[] = {"Radiosity",        "Irradiance",        "Radiance", "Reference",
                                                    "AmbientOcclusion", "AmbientObscurance", "Thickness"};
// Those of them whose filters paint greys (the last three above).
inline constexpr const char* kGreyResultAttributes[] = {"AmbientOcclusion", "AmbientObscurance", "Thickness"};
// Whether vertex colours `colors` display the result attribute `name` a
// mesh holds: the lighting results' always; AO's, obscurance's and
// thickness's only while every colour is still a grey (r = g = b), as those
// filters paint them: colours painted since, or a property of that name
// another tool wrote beside real colours, stay the surface's.
bool colorsDisplay(const std::string& name, const std::vector<glm::u8vec3>& colors);

// Appends part b's colours (faces nf0.., vertices nv0..) to a's, with the
// given-masks above: a part without face or vertex colours gets the filler
// (sRGB 188) marked not given; `bShows` names b's result attribute (its
// vertex colours then count as not given).
void appendColors(MeshAttributes& a, size_t nf0, size_t nv0, const MeshAttributes& b, size_t nf1, size_t nv1,
                  const std::string& bShows);
// Clears a given-mask that marks every colour given (one mesh's rule then).
void dropFullColorMasks(MeshAttributes& a);

enum class EmitterSource { SelectedFaces, QualityAbove, None, Auto };
inline constexpr auto kEmitterSources = makeEnumTable<EmitterSource>({
    {EmitterSource::SelectedFaces, "Selected faces", "the selected faces"},
    {EmitterSource::QualityAbove, "Face quality above threshold", "faces with quality above the threshold"},
    {EmitterSource::None, "None", "none"},
    {EmitterSource::Auto, "Auto", "auto"},
});
enum class ReflectanceSource { Auto, FaceColor, VertexColor, Constant };
inline constexpr auto kReflectanceSources = makeEnumTable<ReflectanceSource>({
    {ReflectanceSource::Auto, "Auto", "auto"},
    {ReflectanceSource::FaceColor, "Face color", "face colour"},
    {ReflectanceSource::VertexColor, "Vertex color", "vertex colour"},
    {ReflectanceSource::Constant, "Constant", "constant"},
});
// Which meshes form the scene (MeshLab only: the CLI's scene is its files).
enum class SceneExtent { CurrentLayer, AllVisibleLayers };
inline constexpr auto kSceneExtents = makeEnumTable<SceneExtent>({
    {SceneExtent::CurrentLayer, "Current layer", "current layer"},
    {SceneExtent::AllVisibleLayers, "All visible layers", "all visible layers"},
});

// Scene parameters shared by radiosity, photon mapping and the reference.
std::vector<ParamSpec> lightingSceneSpecs();
// Only the reflectance/extent part (ambient occlusion needs no emitters).
std::vector<ParamSpec> geometrySceneSpecs();
// Display parameters (exposure) shared by every filter with radiometric output.
std::vector<ParamSpec> displaySpecs();

// Sets rho (and, if withEmitters, emission) of `s` from its attributes.
// Returns an error sentence when the result cannot be used.
std::optional<std::string> applySceneConventions(Scene& s, const MeshAttributes& a, const ParamValues& v,
                                                 bool withEmitters, std::string* log = nullptr);
// White colours (rho >= 1, limited to 0.999) on the diffuse faces, said as a
// warning; mirror, glass and glossy faces take their own colours, which may
// be 1 (so: after applyMaterials).
std::optional<std::string> whiteReflectanceWarning(const Scene& s);

// Mirror and glass (photon mapping and the reference): which layers are
// specular, by name patterns, and their colour and index of refraction.
std::vector<ParamSpec> materialSpecs();

// Glossy layers (the ray tracer, photon mapping, the reference): name
// patterns, GGX roughness and specular colour. Apart from materialSpecs so
// that filters without glossy shading do not offer it; applyMaterials reads
// them when present.
std::vector<ParamSpec> glossySpecs();

// The optional point or spot light's parameters (photon mapping and the reference).
std::vector<ParamSpec> pointLightSpecs();
// Its position relative to sceneOrigin, in world units (as the options hold it).
PointLight pointLightFromParams(const ParamValues& v, const glm::dvec3& sceneOrigin);
// The light in the scene's local units (Scene::unit): position / unit and,
// since its irradiance I cos / r^2 must not change when r is measured in
// local units, intensity / unit^2. The algorithms convert on entry.
PointLight pointLightInLocalUnits(const PointLight& L, const Scene& s);

// A named range of faces of the scene: a MeshLab layer or an input file.
struct LayerRange {
  std::string name;
  size_t faceOffset = 0, faceCount = 0;
};
// Marks the faces of layers whose name matches mirror_layers / glass_layers
// (comma-separated shell patterns, case-insensitive) as Mirror / Glass with
// the specular colour and index of refraction, and, if `v` has the
// glossySpecs parameters, those matching glossy_layers as Glossy (colour and
// roughness from them). Emitter faces stay diffuse.
// Returns an error sentence for unusable settings; *log gets a summary,
// *warnings what makes the result wrong (a closed glass layer turned inside
// out).
std::optional<std::string> applyMaterials(Scene& s, const std::vector<LayerRange>& layers, const ParamValues& v,
                                          std::string* log = nullptr, std::vector<std::string>* warnings = nullptr);
// True if `name` matches one of the comma-separated patterns.
bool matchesLayerPatterns(const std::string& name, const std::string& patterns);

// Per-vertex results in the common output convention.
struct VertexOutput {
  std::vector<float> quality;     // physical scalar (luminance, AO, ...)
  std::vector<glm::vec3> rgb;     // linear values to display (empty: grey from quality)
  float exposure = 1.f;           // applied before sRGB encoding
  std::vector<Rgb8> displayColors() const;
};

// Vertex values from per-face values: area-weighted mean of incident usable faces.
std::vector<glm::vec3> faceToVertex(const Scene& s, const std::vector<glm::vec3>& perFace);
// The same weighted by each face's seen share (gi/patch_seen.h; empty: all
// seen): the mean over the surface the scene sees around the vertex, so a
// patch buried under a block neither darkens the vertices it shares with
// the floor beside it nor, seen in a sliver, lends its noisy value whole.
std::vector<glm::vec3> faceToVertex(const Scene& s, const std::vector<glm::vec3>& perFace,
                                    const std::vector<float>& seenShare);

}  // namespace gi

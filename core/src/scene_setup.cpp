#include "gi/scene_setup.h"

#include <fnmatch.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <limits>
#include <map>
#include <sstream>

namespace gi {

std::vector<ParamSpec> geometrySceneSpecs() {
  std::vector<ParamSpec> s;
  s.push_back({.name = "scene_extent", .label = "Scene extent",
               .help = "Which meshes form the scene. 'Current layer': only the selected layer casts and receives. "
                       "'All visible layers': every visible layer occludes (and reflects) as one scene and every one "
                       "of them receives the result, e.g. a Cornell box built from several meshes.",
               .type = ParamType::Enum, .def = kSceneExtents.index(SceneExtent::CurrentLayer),
               .choices = kSceneExtents.choices(), .meshlabOnly = true});
  s.push_back({.name = "reflectance_source", .label = "Reflectance from",
               .help = "Where the diffuse reflectance (albedo) rho of each face comes from. 'Auto': face colour if "
                       "the mesh has face colours, else the mean of its vertex colours, else the constant below. Vertex "
                       "colours that show the light a lighting filter of this suite computed (its result's display) "
                       "are no reflectance: 'Auto' then takes the constant. Colours are sRGB and are converted to linear reflectance. Every channel must stay below 1 "
                       "(energy conservation).",
               .type = ParamType::Enum, .def = kReflectanceSources.index(ReflectanceSource::Auto),
               .choices = kReflectanceSources.choices()});
  s.push_back({.name = "reflectance", .label = "Constant reflectance",
               .help = "Reflectance used when the mesh has no colours or 'Constant' is chosen (sRGB colour; 0.5 "
                       "linear is sRGB 188).",
               .type = ParamType::Color, .defVec = glm::vec3(188.f / 255.f)});
  return s;
}

std::vector<ParamSpec> lightingSceneSpecs() {
  auto s = geometrySceneSpecs();
  s.push_back({.name = "emitter_source", .label = "Emitters",
               .help = "Which faces emit light. 'Selected faces': select the light in MeshLab (or with a selection "
                       "filter in a script). 'Face quality above threshold': faces whose quality exceeds the "
                       "threshold below. 'None': only for scenes lit otherwise. 'Auto' (the default): the selected "
                       "faces if any face is selected, else the faces with quality above the threshold (the log says "
                       "which).",
               .type = ParamType::Enum, .def = kEmitterSources.index(EmitterSource::Auto),
               .choices = kEmitterSources.choices()});
  s.push_back({.name = "emitter_quality_threshold", .label = "Emitter quality threshold",
               .help = "With 'Face quality above threshold', faces with quality strictly above this value emit.",
               .type = ParamType::Float, .def = 0.5, .min = -1e30, .max = 1e30});
  s.push_back({.name = "emitter_color", .label = "Emitter colour",
               .help = "Chromaticity of the emitted light (sRGB colour, converted to linear).",
               .type = ParamType::Color, .defVec = glm::vec3(1.f, 219.f / 255.f, 133.f / 255.f)});
  s.push_back({.name = "emitter_intensity", .label = "Emitter radiosity (W/m^2)",
               .help = "Emitted radiosity E (exitance, one-sided, towards the face normal) = intensity x linear "
                       "colour. The default reproduces the Cornell box light of radiance (17, 12, 4): E = pi x 17 "
                       "for red.",
               .type = ParamType::Float, .def = 53.407, .min = 0.0, .max = 1e12});
  return s;
}

std::vector<ParamSpec> materialSpecs() {
  std::vector<ParamSpec> s;
  s.push_back({.name = "mirror_layers", .label = "Mirror layers",
               .help = "Layers that are perfect mirrors: comma-separated layer names as the Layer dialog shows them "
                       "(the file name unless renamed; double-click a layer to rename it), with * matching any text, "
                       "e.g. 'mirror*, *.stl'. Case does not matter. Empty: no mirrors.",
               .type = ParamType::String, .defText = "*mirror*"});
  s.push_back({.name = "glass_layers", .label = "Glass layers",
               .help = "Layers made of glass (a smooth dielectric: Fresnel reflection, refraction, total internal "
                       "reflection). Give each glass object as a closed mesh with outward normals. Same patterns as "
                       "for mirrors; empty: no glass.",
               .type = ParamType::String, .defText = "*glass*"});
  s.push_back({.name = "ior", .label = "Index of refraction",
               .help = "Index of refraction of the glass (1.5: window glass, 1.33: water, 2.42: diamond; 1.0 makes "
                       "the glass vanish).",
               .type = ParamType::Float, .def = 1.5, .min = 1.0, .max = 4.0});
  s.push_back({.name = "specular_color", .label = "Mirror and glass colour",
               .help = "Reflectance of the mirrors and transmittance tint of the glass (sRGB; white = a perfect "
                       "mirror and clear glass).",
               .type = ParamType::Color, .defVec = glm::vec3(1.f)});
  return s;
}

std::vector<ParamSpec> glossySpecs() {
  return {{.name = "glossy_layers", .label = "Glossy layers",
           .help = "Layers with a glossy (rough metal) surface: a GGX microfacet reflector (Walter et al. 2007) that "
                   "blurs reflections more as its roughness grows. Same patterns as for mirrors; empty: none.",
           .type = ParamType::String, .defText = "*glossy*"},
          {.name = "glossy_roughness", .label = "Glossy roughness (alpha)",
           .help = "Width alpha of the GGX distribution of microfacet normals: 0.01 nearly a mirror, 0.1 polished, "
                   "0.3 brushed, 1 very rough (the reflected highlight spreads over roughly alpha radians).",
           .type = ParamType::Float, .def = 0.2, .min = 0.001, .max = 1.0},
          {.name = "glossy_color", .label = "Glossy colour",
           .help = "Reflectance of the glossy surfaces at normal incidence (F0 of Schlick's Fresnel term, sRGB); "
                   "towards grazing angles every colour tends to white. White: no light absorbed by the microfacets.",
           .type = ParamType::Color, .defVec = glm::vec3(1.f)}};
}

std::vector<ParamSpec> pointLightSpecs() {
  return {
      {.name = "point_position", .label = "Point light position",
       .help = "Position of an optional point or spot light (absolute coordinates).",
       .type = ParamType::Point, .defVec = glm::vec3(0.f)},
      {.name = "point_intensity", .label = "Point light intensity (W/sr)",
       .help = "Radiant intensity of the point or spot light; 0 = none. Its power is 4 pi I (point) or 2 pi (1 - cos "
               "a) I (spot of half angle a). Its irradiance I cos(theta) / d^2 takes the distance d in the mesh's units: "
               "W/m^2 for a mesh in metres, W/mm^2 for one in millimetres (give I 1e6 times larger there for the "
               "same light in W/m^2); the light of emitting faces, sun and sky does not depend on the unit.",
       .type = ParamType::Float, .def = 0.0, .min = 0.0, .max = 1e12},
      {.name = "point_color", .label = "Point light colour",
       .help = "Colour of the point or spot light (sRGB).",
       .type = ParamType::Color, .defVec = glm::vec3(1.f)},
      {.name = "spot_direction", .label = "Spot direction",
       .help = "Axis of the spot light's cone.",
       .type = ParamType::Direction, .defVec = glm::vec3(0.f, -1.f, 0.f)},
      {.name = "spot_angle", .label = "Spot half angle (deg)",
       .help = "Half angle of the spot's cone (uniform intensity inside, none outside); 180 = a point light shining "
               "every way. At least 0.1: a narrower cone holds no direction but its axis in single precision.",
       .type = ParamType::Float, .def = 180.0, .min = PointLight::kMinSpotAngleDeg, .max = 180.0},
  };
}

PointLight pointLightFromParams(const ParamValues& v, const glm::dvec3& origin) {
  PointLight p;
  p.position = glm::vec3(v.getPoint("point_position") - origin);
  const glm::vec3 c = v.getVec("point_color");
  p.intensity = float(v.getFloat("point_intensity")) * glm::vec3(srgbToLinear(c.r), srgbToLinear(c.g), srgbToLinear(c.b));
  p.spotDirection = v.getDirection("spot_direction");
  p.spotAngleDeg = float(v.getFloat("spot_angle"));
  return p;
}

PointLight pointLightInLocalUnits(const PointLight& L, const Scene& s) {
  PointLight p = L;
  p.position = glm::vec3(glm::dvec3(L.position) / s.unit);
  const glm::dvec3 local = glm::dvec3(L.intensity) / (s.unit * s.unit);
  // Intensity over area: in a scene of 1e-18 m a lamp of 1e12 W/sr is 1e48
  // in the scene's units, beyond single precision (photon mapping crashed on
  // it, the reference wrote its infinite values as 0; an outside audit).
  if (!(std::max({local.x, local.y, local.z}) <= double(std::numeric_limits<float>::max()))) {
    char msg[320];
    std::snprintf(msg, sizeof msg,
                  "point_intensity = %g W/sr is too strong for a scene %.3g across: in the scene's units (I / unit^2) it "
                  "lies beyond single precision (3.4e38); lower it or scale the scene up",
                  double(std::max({L.intensity.x, L.intensity.y, L.intensity.z})), s.unit * double(sceneScale(s).diagonal));
    throw std::invalid_argument(msg);
  }
  p.intensity = glm::vec3(local);
  return p;
}

bool matchesLayerPatterns(const std::string& name, const std::string& patterns) {
  std::stringstream ss(patterns);
  std::string item;
  while (std::getline(ss, item, ',')) {
    const size_t a = item.find_first_not_of(" \t"), b = item.find_last_not_of(" \t");
    if (a == std::string::npos) continue;
    if (fnmatch(item.substr(a, b - a + 1).c_str(), name.c_str(), FNM_CASEFOLD) == 0) return true;
  }
  return false;
}

std::optional<std::string> applyMaterials(Scene& s, const std::vector<LayerRange>& layers, const ParamValues& v,
                                          std::string* log, std::vector<std::string>* warnings) {
  const std::string mirrors = v.getString("mirror_layers"), glass = v.getString("glass_layers");
  const float ior = float(v.getFloat("ior"));
  if (!(ior >= 1.f)) return std::string("the index of refraction must be >= 1");
  const glm::vec3 c = v.getVec("specular_color");
  const glm::vec3 tint(srgbToLinear(c.r), srgbToLinear(c.g), srgbToLinear(c.b));
  const size_t nf = s.faceCount();
  s.material.assign(nf, Material::Diffuse);
  s.ior.assign(nf, ior);
  std::string msg;
  size_t keptEmitters = 0;
  // Glossy layers only where the caller offers them (glossySpecs).
  const bool withGlossy = v.has("glossy_layers");
  if (withGlossy) s.roughness.assign(nf, float(v.getFloat("glossy_roughness")));
  for (const LayerRange& l : layers) {
    const bool m = matchesLayerPatterns(l.name, mirrors), g = matchesLayerPatterns(l.name, glass);
    const bool gl = withGlossy && matchesLayerPatterns(l.name, v.getString("glossy_layers"));
    if (int(m) + int(g) + int(gl) > 1) return "layer '" + l.name + "' matches more than one of the mirror, glass and glossy patterns";
    if (!m && !g && !gl) continue;
    const Material mat = m ? Material::Mirror : g ? Material::Glass : Material::Glossy;
    const glm::vec3 c2 = gl ? v.getVec("glossy_color") : glm::vec3(0.f);
    const glm::vec3 colour = gl ? glm::vec3(srgbToLinear(c2.r), srgbToLinear(c2.g), srgbToLinear(c2.b)) : tint;
    size_t count = 0;
    for (size_t f = l.faceOffset; f < std::min(nf, l.faceOffset + l.faceCount); ++f) {
      if (luminance(s.faceEmission(f)) > 0.f) { ++keptEmitters; continue; }
      s.material[f] = mat;
      s.rho[f] = colour;  // the specular colour (may be 1: a perfect mirror)
      ++count;
    }
    msg += std::string(msg.empty() ? "" : ", ") + "'" + l.name + "' " + (m ? "mirror" : g ? "glass" : "glossy") + " (" +
           std::to_string(count) + " faces)";
    if (g) {  // a glass object should be closed: every edge (by position) shared by two of its faces
      std::map<std::array<float, 3>, uint32_t> at;  // a welded index per position (an STL's corners are apart)
      const auto id = [&](uint32_t v) {
        const glm::vec3& p = s.positions[v];
        return at.emplace(std::array<float, 3>{p.x, p.y, p.z}, uint32_t(at.size())).first->second;
      };
      std::map<std::pair<uint32_t, uint32_t>, int> edges;
      for (size_t f = l.faceOffset; f < std::min(nf, l.faceOffset + l.faceCount); ++f)
        for (int k = 0; k < 3; ++k) {
          const uint32_t a = id(s.triangles[f][k]), b = id(s.triangles[f][(k + 1) % 3]);
          if (a != b) edges[{std::min(a, b), std::max(a, b)}]++;
        }
      const size_t open = size_t(std::count_if(edges.begin(), edges.end(), [](const auto& e) { return e.second != 2; }));
      if (open) msg += " [not closed: " + std::to_string(open) + " border or non-manifold edges]";
      // Refraction needs an inside: light entering an open sheet of glass
      // never leaves it through a second face (a lone pane bends every ray
      // that passes it). Said only in the log until an outside audit.
      if (open && warnings)
        warnings->push_back("glass layer '" + l.name + "' is not closed (" + std::to_string(open) +
                            " border or non-manifold edges): light that enters it may not leave through a second "
                            "face, and the light through it is wrong; give it a thickness (a pane is a thin box)");
      // A closed object whose faces point inwards encloses a negative
      // volume (the divergence theorem: V = sum over faces of a . (b x c) / 6,
      // about the layer's first vertex for precision): light then enters
      // it as if leaving glass, totally reflected beyond the critical angle
      // (an outside audit: a glass slab's caustic under a point light read
      // 0.84 to 0.014 of the exact value, the default sphere's peak 0.28 of
      // 41.4, without a word).
      if (!open && warnings && l.faceCount > 0 && l.faceOffset < nf) {
        const glm::dvec3 o(s.positions[s.triangles[l.faceOffset].x]);
        double six = 0.0, scale = 0.0;
        for (size_t f = l.faceOffset; f < std::min(nf, l.faceOffset + l.faceCount); ++f) {
          const glm::dvec3 a = glm::dvec3(s.positions[s.triangles[f].x]) - o, b = glm::dvec3(s.positions[s.triangles[f].y]) - o,
                           e = glm::dvec3(s.positions[s.triangles[f].z]) - o;
          const double vol = glm::dot(a, glm::cross(b, e));
          six += vol;
          scale += std::fabs(vol);
        }
        if (six < -1e-9 * scale)
          warnings->push_back("glass layer '" + l.name + "' is turned inside out (its faces point inwards: a negative "
                              "enclosed volume), so light meets it as if leaving the glass and the caustics and "
                              "the light through it are wrong; invert its faces' orientation (MeshLab: Normals, "
                              "Curvatures and Orientation > Invert Faces Orientation)");
      }
    }
  }
  if (msg.empty()) {
    msg = "all surfaces diffuse (no layer matches the mirror or glass patterns)";
  } else {
    char b[32];
    std::snprintf(b, sizeof b, "%g", ior);
    msg = "specular: " + msg + ", index of refraction " + b + " (their own colours replaced by the mirror and glass colour)";
  }
  if (keptEmitters) msg += "; " + std::to_string(keptEmitters) + " emitter faces in those layers stay diffuse emitters";
  if (log) *log = msg;
  return std::nullopt;
}

std::vector<ParamSpec> displaySpecs() {
  return {{.name = "exposure", .label = "Exposure",
           .help = "Vertex colour = sRGB(exposure x linear value); 0 chooses it automatically so that the 99th "
                   "percentile of the luminance maps to white. Quality always holds the physical value.",
           .type = ParamType::Float, .def = 0.0, .min = 0.0, .max = 1e12}};
}

bool colorsDisplay(const std::string& name, const std::vector<glm::u8vec3>& colors) {
  if (std::none_of(std::begin(kGreyResultAttributes), std::end(kGreyResultAttributes), [&](const char* g) { return name == g; }))
    return true;
  return std::all_of(colors.begin(), colors.end(), [](const glm::u8vec3& c) { return c.r == c.g && c.g == c.b; });
}

namespace {

// rho per face from the chosen source (rho >= 1 limited to 0.999), *msg the
// log's part ("reflectance from ..."); the error sentence when the mesh lacks
// that source.
std::optional<std::string> setReflectance(Scene& s, const MeshAttributes& a, const ParamValues& v, std::string* msg) {
  const size_t nf = s.faceCount(), nv = s.vertexCount();
  auto src = kReflectanceSources.get(v, "reflectance_source");
  const glm::vec3 constant = v.getVec("reflectance");
  const glm::vec3 constantLin(srgbToLinear(constant.r), srgbToLinear(constant.g), srgbToLinear(constant.b));
  const bool hasFace = a.faceColor.size() == nf && nf > 0;
  const bool hasVert = a.vertexColor.size() == nv && nv > 0;
  const bool faceMask = a.faceColorGiven.size() == nf, vertMask = a.vertexColorGiven.size() == nv;
  const bool auto_ = src == ReflectanceSource::Auto;
  // One mesh whose vertex colours display a result (with layers, the masks say it per layer).
  const bool resultColors = auto_ && !hasFace && hasVert && !vertMask && !a.vertexColorShows.empty();
  auto faceGiven = [&](size_t f) { return hasFace && (!faceMask || a.faceColorGiven[f]); };
  auto vertGiven = [&](uint32_t i) { return i < nv && hasVert && !resultColors && (!vertMask || a.vertexColorGiven[i]); };
  if (src == ReflectanceSource::FaceColor && !hasFace) return std::string("reflectance from face colour was asked for, but the mesh has no face colours");
  if (src == ReflectanceSource::VertexColor && !hasVert) return std::string("reflectance from vertex colour was asked for, but the mesh has no vertex colours");
  s.rho.assign(nf, constantLin);
  size_t used[3] = {0, 0, 0};  // faces from face colour, vertex colour, the constant
  for (size_t f = 0; f < nf; ++f) {
    const auto& t = s.triangles[f];
    // Per face (Auto): its own colour, else its vertices', else the constant;
    // a source asked for by name, where the face's layer has it.
    const bool byFace = (auto_ || src == ReflectanceSource::FaceColor) && faceGiven(f);
    const bool byVert = !byFace && (auto_ || src == ReflectanceSource::VertexColor) && vertGiven(t.x) &&
                        vertGiven(t.y) && vertGiven(t.z);
    if (byFace) {
      const auto& c = a.faceColor[f];
      s.rho[f] = srgb8ToLinear(c.r, c.g, c.b);
      ++used[0];
    } else if (byVert) {
      glm::vec3 sum(0.f);
      for (int k = 0; k < 3; ++k) {
        if (t[k] >= nv) continue;
        const auto& c = a.vertexColor[t[k]];
        sum += srgb8ToLinear(c.r, c.g, c.b);
      }
      s.rho[f] = sum / 3.f;
      ++used[1];
    } else {
      ++used[2];
    }
  }
  if (auto_)
    src = used[0] == nf ? ReflectanceSource::FaceColor : used[1] == nf ? ReflectanceSource::VertexColor : ReflectanceSource::Constant;
  const bool mixed = used[0] != nf && used[1] != nf && used[2] != nf;
  // Energy conservation: a white 255 colour is rho = 1, which never converges.
  size_t clamped = 0;
  for (auto& r : s.rho)
    for (int k = 0; k < 3; ++k)
      if (r[k] > 0.999f) { r[k] = 0.999f; ++clamped; }
  *msg = std::string("reflectance from ") + kReflectanceSources.logName(src);
  if (mixed)
    *msg = "reflectance per layer: from face colour on " + std::to_string(used[0]) + " faces, from vertex colour on " +
           std::to_string(used[1]) + ", the constant on " + std::to_string(used[2]) + " (layers without those colours)";
  if (resultColors)
    *msg += " (the vertex colours display an earlier filter's result, " + a.vertexColorShows +
            ", not a reflectance: choose 'Vertex color' to use them anyway)";
  if (clamped) *msg += " (" + std::to_string(clamped) + " channels of white colours limited to 0.999)";
  return std::nullopt;
}

}  // namespace

void appendColors(MeshAttributes& a, size_t nf0, size_t nv0, const MeshAttributes& b, size_t nf1, size_t nv1,
                  const std::string& bShows) {
  // The masks of a's part (all given where it has colours and no mask yet) and of b's.
  auto given = [](std::vector<uint8_t>& mask, bool has, size_t n) {
    if (mask.size() != n) mask.assign(n, has ? 1 : 0);
  };
  const bool aShows = !a.vertexColorShows.empty() && a.vertexColorGiven.empty();
  if (!a.faceColor.empty() || !b.faceColor.empty()) {
    given(a.faceColorGiven, !a.faceColor.empty(), nf0);
    a.faceColor.resize(nf0, glm::u8vec3(188));
    a.faceColorGiven.insert(a.faceColorGiven.end(), nf1, b.faceColor.empty() ? 0 : 1);
    if (b.faceColor.empty()) a.faceColor.insert(a.faceColor.end(), nf1, glm::u8vec3(188));
    else a.faceColor.insert(a.faceColor.end(), b.faceColor.begin(), b.faceColor.end());
  }
  if (!a.vertexColor.empty() || !b.vertexColor.empty()) {
    given(a.vertexColorGiven, !a.vertexColor.empty() && !aShows, nv0);
    a.vertexColor.resize(nv0, glm::u8vec3(188));
    a.vertexColorGiven.insert(a.vertexColorGiven.end(), nv1, b.vertexColor.empty() || !bShows.empty() ? 0 : 1);
    if (b.vertexColor.empty()) a.vertexColor.insert(a.vertexColor.end(), nv1, glm::u8vec3(188));
    else a.vertexColor.insert(a.vertexColor.end(), b.vertexColor.begin(), b.vertexColor.end());
  }
  if (a.vertexColorShows.empty()) a.vertexColorShows = bShows;
  dropFullColorMasks(a);
}

void dropFullColorMasks(MeshAttributes& a) {
  for (std::vector<uint8_t>* mask : {&a.faceColorGiven, &a.vertexColorGiven})
    if (std::all_of(mask->begin(), mask->end(), [](uint8_t g) { return g != 0; })) mask->clear();
}

namespace {

// E per face from the chosen source (Auto: the selection if any face is
// selected, else face quality); the log's part.
std::string setEmission(Scene& s, const MeshAttributes& a, const ParamValues& v) {
  const size_t nf = s.faceCount();
  const auto es = kEmitterSources.get(v, "emitter_source");
  const glm::vec3 col = v.getVec("emitter_color");
  const glm::vec3 E =
      float(v.getFloat("emitter_intensity")) * glm::vec3(srgbToLinear(col.r), srgbToLinear(col.g), srgbToLinear(col.b));
  s.emission.assign(nf, glm::vec3(0.f));
  size_t count = 0;
  const bool anySelected = a.faceSelected.size() == nf &&
                           std::any_of(a.faceSelected.begin(), a.faceSelected.end(), [](uint8_t x) { return x != 0; });
  const EmitterSource chosen = es != EmitterSource::Auto ? es
                               : anySelected        ? EmitterSource::SelectedFaces
                                                    : EmitterSource::QualityAbove;
  std::string msg;
  if (es == EmitterSource::Auto)
    msg = std::string("; emitters: ") + kEmitterSources.logName(chosen) + (anySelected ? "" : " (nothing selected)");
  if (chosen == EmitterSource::SelectedFaces && a.faceSelected.size() == nf) {
    for (size_t f = 0; f < nf; ++f)
      if (a.faceSelected[f]) { s.emission[f] = E; ++count; }
  } else if (chosen == EmitterSource::QualityAbove && a.faceQuality.size() == nf) {
    const float th = float(v.getFloat("emitter_quality_threshold"));
    for (size_t f = 0; f < nf; ++f)
      if (a.faceQuality[f] > th) { s.emission[f] = E; ++count; }
  }
  return msg + "; " + std::to_string(count) + " emitter faces" +
         (count && E == glm::vec3(0.f) ? " emitting nothing (emitter_intensity 0 or emitter_color black)" : "");
}

}  // namespace

std::optional<std::string> applySceneConventions(Scene& s, const MeshAttributes& a, const ParamValues& v,
                                                 bool withEmitters, std::string* log) {
  std::string msg;
  if (auto err = setReflectance(s, a, v, &msg)) return err;
  if (withEmitters) msg += setEmission(s, a, v);
  if (log) *log = msg;
  return std::nullopt;
}

std::optional<std::string> whiteReflectanceWarning(const Scene& s) {
  size_t clamped = 0;
  for (size_t f = 0; f < s.faceCount(); ++f) {
    if (!s.material.empty() && s.material[f] != Material::Diffuse) continue;  // a specular colour may be 1
    const glm::vec3 r = s.faceRho(f);
    for (int k = 0; k < 3; ++k) clamped += r[k] >= 0.999f ? 1 : 0;
  }
  if (!clamped) return std::nullopt;
  return std::to_string(clamped) +
         " reflectance channels of diffuse faces at or above 0.999 (white or nearly white colours) limited to 0.999: rho = 1 returns all "
         "the light it receives, and a closed room never converges; at 0.999 B there reaches about 1000 times the "
         "emission (choose a reflectance below 1)";
}

std::vector<Rgb8> VertexOutput::displayColors() const {
  std::vector<Rgb8> out(quality.size());
  for (size_t i = 0; i < quality.size(); ++i) {
    glm::vec3 c = rgb.empty() ? glm::vec3(quality[i]) : rgb[i];
    out[i] = displayMap(c, exposure);
  }
  return out;
}

std::vector<glm::vec3> faceToVertex(const Scene& s, const std::vector<glm::vec3>& perFace) {
  return faceToVertex(s, perFace, {});
}

std::vector<glm::vec3> faceToVertex(const Scene& s, const std::vector<glm::vec3>& perFace,
                                    const std::vector<float>& seenShare) {
  std::vector<glm::dvec3> acc(s.vertexCount(), glm::dvec3(0.0));
  std::vector<double> w(s.vertexCount(), 0.0);
  const auto ok = usableFaceMask(s);
  for (size_t f = 0; f < s.faceCount(); ++f) {
    if (!ok[f]) continue;
    const double a = faceArea(s, f) * (seenShare.empty() ? 1.0 : double(seenShare[f]));
    if (!(a > 0.0)) continue;
    for (int k = 0; k < 3; ++k) { acc[s.triangles[f][k]] += a * glm::dvec3(perFace[f]); w[s.triangles[f][k]] += a; }
  }
  std::vector<glm::vec3> out(s.vertexCount(), glm::vec3(0.f));
  for (size_t i = 0; i < out.size(); ++i)
    if (w[i] > 0.0) out[i] = glm::vec3(acc[i] / w[i]);
  return out;
}

}  // namespace gi

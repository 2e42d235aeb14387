#include "gi/filters.h"

#include <cmath>
#include <cstdio>
#include <sstream>
#include <stdexcept>

#include "gi/ambient.h"
#include "gi/form_factors.h"
#include "gi/hemicube_view.h"
#include "gi/direct.h"
#include "gi/error_map.h"
#include "gi/pathtrace.h"
#include "gi/photon.h"
#include "gi/radiosity.h"
#include "gi/render.h"
#include "gi/scene_setup.h"
#include "gi/thickness.h"

namespace gi {

std::vector<ParamSpec> filterSpecs(FilterKind k) {
  std::vector<ParamSpec> s;
  auto add = [&s](const std::vector<ParamSpec>& more) { s.insert(s.end(), more.begin(), more.end()); };
  switch (k) {
    case FilterKind::AmbientOcclusion:
    case FilterKind::AmbientObscurance:
    case FilterKind::SkyLighting: {
      const AmbientMode m = k == FilterKind::AmbientOcclusion ? AmbientMode::Occlusion
                            : k == FilterKind::AmbientObscurance ? AmbientMode::Obscurance
                                                                 : AmbientMode::Sky;
      s.push_back(geometrySceneSpecs().front());  // scene extent (reflectance plays no part)
      add(AmbientOptions::specs(m));
      if (m == AmbientMode::Sky) add(displaySpecs());
      break;
    }
    case FilterKind::Thickness:
      s.push_back(geometrySceneSpecs().front());  // scene extent
      add(ThicknessOptions::specs());
      break;
    case FilterKind::Radiosity:
      add(lightingSceneSpecs());
      add(RadiosityOptions::specs());
      s.push_back({.name = "face_output", .label = "Also write per-face results",
                   .help = "Besides the per-vertex result (area-weighted mean of the incident patches), write each "
                           "patch's radiosity to face quality and face colour: the flat-shaded look of the course's "
                           "images (a patch partly buried under another surface shows the radiosity of the part the "
                           "scene sees). The faces' own quality and colour are then gone: a later run on this "
                           "result would take every patch brighter than the emitter threshold for a light and the "
                           "displayed colours for reflectances (the Cornell box: 108 emitters instead of 12, 10 "
                           "times the power); run again on the original mesh, or select the lights.",
                   .type = ParamType::Bool, .def = false});
      add(displaySpecs());
      break;
    case FilterKind::PhotonMapping:
      add(lightingSceneSpecs());
      add(materialSpecs());
      add(glossySpecs());
      add(PhotonOptions::specs());
      s.push_back({.name = "photon_layer", .label = "Photons as a new layer",
                   .help = "Also add the stored photons as a point-cloud layer (the command-line tool: a PLY beside "
                           "the output, NAME.Photons.ply): each photon of the maps the estimates read is a point "
                           "where it landed, coloured by its map (global map orange, caustic map blue), with "
                           "quality = its power (luminance, W) and normal = the side it arrived on. Colour by power "
                           "with MeshLab's Colorize by vertex quality. A re-run refills the layer the last run made "
                           "(rename it to keep it). Not with progressive photon mapping, which keeps no map.",
                   .type = ParamType::Bool, .def = false});
      s.push_back({.name = "photon_layer_max", .label = "Most points in the photon layer",
                   .help = "A cap on the photon layer's points (about 40 bytes each in MeshLab): with more stored "
                           "photons, every k-th of each map is kept, evenly, and the log says how many were left "
                           "out. The points keep their own power.",
                   .type = ParamType::Int, .def = 1000000, .min = 1, .max = 100000000});
      add(displaySpecs());
      break;
    case FilterKind::FormFactorsOfFace:
      s.push_back(geometrySceneSpecs().front());  // scene extent
      s.push_back({.name = "face_index", .label = "Face",
                   .help = "The face whose form factors are computed: -1 = the one selected face (MeshLab), else its "
                           "index among the scene's triangles, the layers' one after another (the command-line tool "
                           "needs it; a file's polygon of n corners counts as its n - 2 triangles, in its place, as "
                           "MeshLab counts after loading; in MeshLab a deleted face keeps its number until the layer "
                           "is compacted, and the log's face numbers are MeshLab's).",
                   .type = ParamType::Int, .def = -1, .min = -1, .max = 2147483647});
      add(formFactorSpecs());
      s.push_back(seedSpec("form-factor rays"));
      break;
    case FilterKind::HemicubeOfFace:
      s.push_back(geometrySceneSpecs().front());  // scene extent
      add(hemicubeViewSpecs());
      break;
    case FilterKind::RayTracedView:
      add(lightingSceneSpecs());
      add(materialSpecs());
      add(glossySpecs());
      add(RenderOptions::specs());
      add(displaySpecs());
      break;
    case FilterKind::PathTracedReference:
      add(lightingSceneSpecs());
      add(materialSpecs());
      add(glossySpecs());
      add(PathTraceOptions::specs());
      add(displaySpecs());
      break;
    case FilterKind::ErrorMap:
      s.push_back(geometrySceneSpecs().front());  // scene extent
      add(ErrorMapOptions::specs());
      break;
  }
  return s;
}

static std::string xmlEscape(const std::string& t) {
  std::string o;
  for (char c : t) {
    switch (c) {
      case '&': o += "&amp;"; break;
      case '<': o += "&lt;"; break;
      case '>': o += "&gt;"; break;
      case '"': o += "&quot;"; break;
      default: o += c;
    }
  }
  return o;
}

// MeshLab reads script values as float: 9 significant digits give back exactly
// the float the engine rounds the value to (gi::runFilter).
static std::string fnum(double x) {
  char b[64];
  std::snprintf(b, sizeof b, "%.9g", double(float(x)));
  return b;
}

std::string mlxScript(const std::vector<ScriptStep>& steps, double diagonal) {
  std::ostringstream o;
  o << "<!DOCTYPE FilterScript>\n<FilterScript>\n";
  for (const auto& st : steps) {
    o << " <filter name=\"" << xmlEscape(filterDesc(st.kind).meshlabName) << "\">\n";
    for (const ParamSpec& p : filterSpecs(st.kind)) {
      const std::string n = "name=\"" + p.name + "\"";
      switch (p.type) {
        case ParamType::Bool:
          o << "  <Param type=\"RichBool\" value=\"" << (st.values.getBool(p.name) ? "true" : "false") << "\" " << n << "/>\n";
          break;
        case ParamType::Int:
          o << "  <Param type=\"RichInt\" value=\"" << st.values.getInt(p.name) << "\" " << n << "/>\n";
          break;
        case ParamType::Float:
          o << "  <Param type=\"RichFloat\" value=\"" << fnum(st.values.getFloat(p.name)) << "\" " << n << "/>\n";
          break;
        case ParamType::Distance:
          o << "  <Param type=\"RichAbsPerc\" value=\"" << fnum(st.values.getFloat(p.name)) << "\" min=\"0\" max=\""
            << fnum((p.max > 0 ? p.max : 1.0) * (diagonal > 0 ? diagonal : 1.0)) << "\" " << n << "/>\n";
          break;
        case ParamType::Enum: {
          o << "  <Param type=\"RichEnum\" value=\"" << st.values.getInt(p.name) << "\" enum_cardinality=\""
            << p.choices.size() << "\"";
          for (size_t i = 0; i < p.choices.size(); ++i) o << " enum_val" << i << "=\"" << xmlEscape(p.choices[i]) << "\"";
          o << " " << n << "/>\n";
          break;
        }
        case ParamType::Color: {
          const glm::vec3 c = st.values.getVec(p.name);
          auto b = [](float x) { return int(std::lround(x * 255.f)); };
          o << "  <Param type=\"RichColor\" r=\"" << b(c.r) << "\" g=\"" << b(c.g) << "\" b=\"" << b(c.b)
            << "\" a=\"255\" " << n << "/>\n";
          break;
        }
        case ParamType::Direction:
        case ParamType::Point: {
          const glm::dvec3 d = p.type == ParamType::Point ? st.values.getPoint(p.name) : glm::dvec3(st.values.getVec(p.name));
          o << "  <Param type=\"RichPoint3f\" x=\"" << fnum(d.x) << "\" y=\"" << fnum(d.y) << "\" z=\"" << fnum(d.z)
            << "\" " << n << "/>\n";
          break;
        }
        case ParamType::String:
          o << "  <Param type=\"RichString\" value=\"" << xmlEscape(st.values.getString(p.name)) << "\" " << n << "/>\n";
          break;
      }
    }
    o << " </filter>\n";
  }
  o << "</FilterScript>\n";
  return o.str();
}

}  // namespace gi

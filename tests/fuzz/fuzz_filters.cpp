// libFuzzer target of the filters: every input is read as a small scene (a
// few vertices and triangles, coordinates from a palette of hostile values
// or raw float bits, colours, qualities and selections) and a filter with
// small budgets, the way a MeshLab layer reaches the engine (indices in
// range, anything else possible: NaN, Inf, 1e30, repeated corners, a point).
// runFilter may only return a result that holds together (arrays of the
// scene's sizes, finite values) or throw std::invalid_argument or
// std::runtime_error (the documented refusals); anything else (a crash, a
// sanitizer report, another exception, a NaN written out, a hang) is a
// finding. For ambient occlusion per vertex, the open-vertex proofs must
// also leave every value as the rays give it (openVertexOracle).
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <map>
#include <optional>
#include <stdexcept>
#include <string>

#include "gi/ambient.h"
#include "gi/filter_run.h"
#include "gi/filters.h"
#include "gi/params.h"
#include "gi/raycaster.h"
#include "gi/scene.h"

namespace {

[[noreturn]] void finding(const std::string& kind, const char* what) {
  std::fprintf(stderr, "gi_fuzz_filters: %s: %s\n", kind.c_str(), what);
  std::abort();
}

// The input's bytes, read from the front; zeros once they run out.
struct Bytes {
  const uint8_t* p;
  size_t n;
  uint8_t u8() { return n ? (--n, *p++) : 0; }
  float raw() {
    uint32_t b = 0;
    for (int k = 0; k < 4; ++k) b = b << 8 | u8();
    float f;
    std::memcpy(&f, &b, 4);
    return f;
  }
  // A coordinate: mostly small grid values (scenes that hold together),
  // sometimes a hostile one or raw bits.
  float coord() {
    static const float kPalette[] = {0.f, 1.f, -1.f, 0.5f, 2.f, 1e-30f, -1e-30f, 1e30f, -1e30f, 1e-7f, 3e18f,
                                     std::numeric_limits<float>::denorm_min(), std::numeric_limits<float>::quiet_NaN(),
                                     std::numeric_limits<float>::infinity(), -std::numeric_limits<float>::infinity(),
                                     1.0000001f};
    const uint8_t c = u8();
    if (c < 160) return float(int(c % 9) - 4) * 0.25f;
    if (c < 240) return kPalette[c % 16];
    return raw();
  }
};

using Params = std::map<std::string, std::string>;

// Small budgets per filter (a run takes milliseconds), with a few choices
// from the input's bytes. Refined radiosity stops at 48 patches: the
// analytic method's pairs at a thin fold refine thousands of times each, as
// they must, and at 100 patches a 16-face fold took 25 s sanitized, near
// the 30 s that counts as a hang.
Params budget(gi::FilterKind kind, Bytes& in) {
  const uint8_t a = in.u8(), b = in.u8();
  switch (kind) {
    case gi::FilterKind::AmbientOcclusion:
      // 128 rays per vertex (a & 8): the per-vertex estimator's proof that a
      // vertex is open for rays of any length runs from there.
      return {{"rays_per_vertex", a & 8 ? "128" : "8"}, {"estimator", std::to_string(a % 2)},
              {"target_error", b % 2 ? "0.2" : "0"}, {"max_rays", "32"}, {"bent_normals", a & 2 ? "true" : "false"},
              {"use_cone", a & 4 ? "true" : "false"}};
    case gi::FilterKind::AmbientObscurance:
      return {{"rays_per_vertex", "8"}, {"estimator", std::to_string(a % 2)}, {"max_rays", "32"}};
    case gi::FilterKind::SkyLighting:
      return {{"rays_per_vertex", "8"}, {"sun_rays", "2"}, {"max_rays", "32"}};
    case gi::FilterKind::Thickness:
      return {{"rays_per_vertex", "8"}, {"max_rays", "32"}, {"target_error", b % 2 ? "0.2" : "0"}};
    case gi::FilterKind::Radiosity:
      return {{"rays_per_patch", "16"}, {"form_factor_method", std::to_string(a % 3)}, {"solver", std::to_string(b % 4)},
              {"hemicube_resolution", "16"}, {"max_iterations", "20"}, {"gather_rays", "4"}, {"link_rays", "2"},
              {"max_links", "2000"}, {"sky_irradiance", "1"}, {"refine", a & 8 ? "true" : "false"},
              {"refine_max_patches", "48"}, {"vertex_output", std::to_string((a >> 4) % 3)}};
    case gi::FilterKind::PhotonMapping:
      return {{"photons", "500"}, {"gather_rays", "2"}, {"final_gather", a & 1 ? "true" : "false"},
              {"progressive", a & 2 ? "true" : "false"}, {"passes", "2"}, {"sky_irradiance", "1"},
              {"photon_layer", "true"}, {"photon_layer_max", "100"}, {"light_samples", "2"},
              // A point light at the origin, a grid point of most inputs: on or near their faces.
              {"point_intensity", a & 4 ? "1" : "0"}};
    case gi::FilterKind::PathTracedReference:
      return {{"samples_per_vertex", "4"}, {"min_samples", "4"}, {"max_samples", "8"}, {"max_depth", "3"},
              {"sky_irradiance", "1"}, {"sun_irradiance", a & 1 ? "1" : "0"},
              {"sun_angular_radius", a & 2 ? "1e-6" : "0.27"}};
    case gi::FilterKind::FormFactorsOfFace:
      return {{"face_index", std::to_string(a % 4)}, {"form_factor_method", std::to_string(b % 3)},
              {"rays_per_patch", "16"}, {"hemicube_resolution", "16"}};
    case gi::FilterKind::RayTracedView:
      return {{"mode", std::to_string(a % 4)}, {"width", "8"}, {"height", "6"}, {"samples_per_pixel", "1"},
              {"caustic_photons", "200"}, {"gather_rays", "2"}, {"max_depth", "3"}, {"sky_irradiance", "1"},
              {"light_samples", "1"}};
    case gi::FilterKind::HemicubeOfFace:
      return {{"face_index", std::to_string(a % 4)}, {"hemicube_resolution", "8"}, {"nusselt_resolution", "16"}};
    case gi::FilterKind::ErrorMap:
      return {{"error_measure", std::to_string(a % 3)}, {"value_error", b % 2 ? "StdError" : ""}};
    default:
      return {};
  }
}

void finiteAll(const std::vector<float>& v, const std::string& kind, const char* what) {
  for (float x : v)
    if (!std::isfinite(x)) finding(kind, what);
}
void finiteVecs(const std::vector<glm::vec3>& v, const std::string& kind, const char* what) {
  for (const auto& x : v)
    if (!std::isfinite(x.x) || !std::isfinite(x.y) || !std::isfinite(x.z)) finding(kind, what);
}

// A differential oracle for the open-vertex proofs (gi/open_space.h): per
// vertex at 128 rays (where the proof for rays of any length runs), with rays
// of any length or limited, and half the time the input's own vertex normals
// (a library caller's: any length, hostile values), the values with the
// proofs must be exactly those without, or both runs refuse.
void openVertexOracle(gi::Scene s, Bytes& in) {
  const uint8_t how = in.u8();
  if (how & 1)
    for (size_t i = 0; i < s.vertexCount(); ++i) s.vertexNormals.push_back({in.coord(), in.coord(), in.coord()});
  gi::AmbientOptions o;
  o.raysPerVertex = 128;
  o.maxDistance = how & 2 ? 0.0 : 0.25 * double(1 + (how >> 2));
  auto run = [&](bool skip) -> std::optional<std::vector<float>> {
    try {
      const auto caster = gi::makeEmbreeCaster(s);
      o.skipOpenVertices = skip;
      return gi::computeAmbient(s, *caster, o).value;
    } catch (const std::invalid_argument&) {
      return std::nullopt;
    } catch (const std::runtime_error&) {
      return std::nullopt;
    }
  };
  if (run(true) != run(false)) finding("ambient occlusion", "the open-vertex proofs changed a value");
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  // GI_FUZZ_VERBOSE=1: what each input did, on stderr; 2: also the scene and
  // the parameters (to rerun a finding with `gi`: the scene as OBJ lines).
  static const int verbose = std::getenv("GI_FUZZ_VERBOSE") ? std::atoi(std::getenv("GI_FUZZ_VERBOSE")) : 0;
  Bytes in{data, size};
  static const gi::FilterKind kKinds[] = {
      gi::FilterKind::AmbientOcclusion, gi::FilterKind::AmbientObscurance, gi::FilterKind::SkyLighting,
      gi::FilterKind::Thickness,        gi::FilterKind::Radiosity,         gi::FilterKind::PhotonMapping,
      gi::FilterKind::PathTracedReference, gi::FilterKind::FormFactorsOfFace, gi::FilterKind::RayTracedView,
      gi::FilterKind::HemicubeOfFace,   gi::FilterKind::ErrorMap};
  const gi::FilterKind kind = kKinds[in.u8() % (sizeof kKinds / sizeof kKinds[0])];
  const std::string name = gi::filterDesc(kind).cliName;
  const Params params = budget(kind, in);

  gi::FilterInput fi;
  const size_t nv = 3 + in.u8() % 14, nf = 1 + in.u8() % 20;
  std::vector<glm::dvec3> points;
  std::vector<glm::uvec3> triangles;
  for (size_t i = 0; i < nv; ++i) {
    const float x = in.coord(), y = in.coord(), z = in.coord();
    points.push_back({x, y, z});
  }
  for (size_t f = 0; f < nf; ++f) {
    const uint32_t a = in.u8() % nv, b = in.u8() % nv, c = in.u8() % nv;
    triangles.push_back({a, b, c});
  }
  fi.scene = gi::Scene::fromAbsolute(points, triangles);  // as the front ends fill it
  if (verbose >= 2) {
    std::fprintf(stderr, "%s", name.c_str());
    for (const auto& [k, v] : params) std::fprintf(stderr, " --%s %s", k.c_str(), v.c_str());
    std::fprintf(stderr, "\n");
    for (const auto& q : points) std::fprintf(stderr, "v %.9g %.9g %.9g\n", q.x, q.y, q.z);
    for (const auto& t : triangles) std::fprintf(stderr, "f %u %u %u\n", t.x + 1, t.y + 1, t.z + 1);
  }
  const uint8_t extras = in.u8();
  if (extras & 1)
    for (size_t f = 0; f < nf; ++f) fi.attrs.faceColor.push_back({in.u8(), in.u8(), in.u8()});
  if (extras & 2)
    for (size_t i = 0; i < nv; ++i) fi.attrs.vertexColor.push_back({in.u8(), in.u8(), in.u8()});
  if (extras & 4)
    for (size_t f = 0; f < nf; ++f) fi.attrs.faceQuality.push_back(in.coord());
  if (extras & 8)
    for (size_t f = 0; f < nf; ++f) fi.attrs.faceSelected.push_back(in.u8() & 1);
  if (extras & 16)
    for (size_t i = 0; i < nv; ++i) fi.attrs.vertexSelected.push_back(in.u8() & 1);
  // What earlier filters left per vertex (the error map's value, reference
  // and their standard errors), with the same hostile values.
  if (kind == gi::FilterKind::ErrorMap)
    for (const char* attribute : {"quality", "StdError", "Reference", "ReferenceStdError"}) {
      gi::VertexAttribute a{attribute, 1, {}};
      for (size_t i = 0; i < nv; ++i) a.values.push_back(in.coord());
      fi.attributes.push_back(std::move(a));
    }
  // One layer, or two (the second may be named a mirror or glass layer).
  const size_t split = extras & 32 ? nf / 2 : nf;
  fi.layers.push_back({"mesh", 0, split});
  if (split < nf) fi.layers.push_back({extras & 64 ? "mirror" : "glass", split, nf - split});

  try {
    const auto specs = gi::filterSpecs(kind);
    const double diag = gi::analyzeScene(fi.scene).diagonal;
    fi.values = gi::defaultValues(specs, diag);
    for (const auto& [k, v] : params)
      if (const gi::ParamSpec* s = gi::findSpec(specs, k)) fi.values.set(k, gi::parseValue(*s, v, diag));
    if (extras & 128) {
      for (const char* layers : {"mirror_layers", "glass_layers"})
        if (const gi::ParamSpec* s = gi::findSpec(specs, layers))
          fi.values.set(layers, gi::parseValue(*s, layers[0] == 'm' ? "mirror" : "glass", diag));
    }
    const gi::FilterResult r = gi::runFilter(kind, fi);
    const size_t outV = r.refined ? r.refined->scene.vertexCount() : fi.scene.vertexCount();
    const size_t outF = r.refined ? r.refined->scene.faceCount() : fi.scene.faceCount();
    if (!r.vertexQuality.empty() && r.vertexQuality.size() != outV) finding(name, "vertex quality of the wrong length");
    if (!r.vertexColor.empty() && r.vertexColor.size() != outV) finding(name, "vertex colours of the wrong length");
    if (!r.faceQuality.empty() && r.faceQuality.size() != outF) finding(name, "face quality of the wrong length");
    if (!r.faceColor.empty() && r.faceColor.size() != outF) finding(name, "face colours of the wrong length");
    finiteAll(r.vertexQuality, name, "a non-finite vertex quality");
    finiteAll(r.faceQuality, name, "a non-finite face quality");
    finiteVecs(r.vertexNormal, name, "a non-finite vertex normal");
    for (const auto& a : r.attributes) {
      if (a.values.size() != outV * size_t(a.components)) finding(name, "an attribute of the wrong length");
      finiteAll(a.values, name, "a non-finite attribute value");
    }
    for (const auto& l : r.layers) {
      finiteAll(l.quality, name, "a non-finite quality in a new layer");
      finiteVecs(l.normals, name, "a non-finite normal in a new layer");
    }
    for (const auto& im : r.images) finiteVecs(im.image.px, name, "a non-finite pixel");
    if (verbose) std::fprintf(stderr, "%s: %zu vertices, %zu faces: computed\n", name.c_str(), nv, nf);
    if (kind == gi::FilterKind::AmbientOcclusion && params.at("estimator") == "0") openVertexOracle(fi.scene, in);
  } catch (const std::invalid_argument& e) {
    // unusable input or parameters: the documented refusal
    if (verbose) std::fprintf(stderr, "%s: %zu vertices, %zu faces: refused: %s\n", name.c_str(), nv, nf, e.what());
  } catch (const std::runtime_error& e) {
    // a numerical failure reported as an error (e.g. an unrepresentable ray)
    if (verbose) std::fprintf(stderr, "%s: %zu vertices, %zu faces: error: %s\n", name.c_str(), nv, nf, e.what());
  } catch (const std::exception& e) {
    finding(name, e.what());
  }
  return 0;
}

#include "filter_views.h"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdio>
#include <fstream>
#include <string>
#include <stdexcept>

#include "gi/color.h"
#include "gi/filter_files.h"
#include "gi/form_factors.h"
#include "gi/hemicube_view.h"
#include "gi/output.h"
#include "gi/render.h"
#include "gi/sampling.h"
#include "scene_defects.h"

namespace gi {

std::optional<uint32_t> FilterInput::sceneFace(uint64_t number) const {
  if (faceNumbers.empty()) return number < scene.faceCount() ? std::optional<uint32_t>(uint32_t(number)) : std::nullopt;
  const auto it = std::lower_bound(faceNumbers.begin(), faceNumbers.end(), number);  // increasing
  if (it == faceNumbers.end() || *it != number) return std::nullopt;
  return uint32_t(it - faceNumbers.begin());
}

}  // namespace gi

namespace gi::detail {

namespace {

// The face face_index names (in the front end's numbering), or the one
// selected face.
uint32_t chosenFace(const FilterInput& in) {
  const int k = in.values.getInt("face_index");
  if (k < 0 || in.faceNumbers.empty()) return gi::chosenFace(k, in.attrs.faceSelected, in.scene.faceCount());
  if (const auto f = in.sceneFace(uint64_t(k))) return *f;
  throw std::invalid_argument("face_index " + std::to_string(k) + " names no face of the layers: " +
                              (uint64_t(k) < in.faceNumbers.back() ? std::string("that face was deleted")
                                                                    : "that face was deleted, or lies beyond their "
                                                                      "last, " + std::to_string(in.faceNumbers.back())));
}

// Why a face's row is empty: 64 cosine rays from its centre find only the
// backs of faces (it lies inside a solid: the floor under a block) or
// nothing (it faces away from the scene). The log said "0 faces reached,
// lost 1" alone (an outside audit); radiosity's says which patches are
// buried.
std::string emptyRowReason(const Scene& s, const RayCaster& caster, uint32_t face, uint64_t number) {
  const glm::uvec3& t = s.triangles[face];
  const glm::vec3 n = glm::normalize(faceNormalUnnormalized(s, face));
  const Frame frame(n);
  const float eps = float(sceneScale(s).rayEpsilon);
  int backs = 0, misses = 0;
  constexpr int kRays = 64;
  for (int k = 0; k < kRays; ++k) {
    Ray ray;
    ray.o = (s.positions[t.x] + s.positions[t.y] + s.positions[t.z]) / 3.f + n * eps;
    ray.d = frame.toWorld(cosineHemisphere(sobolOwen2D(uint32_t(k), 0xb0b1u)));
    const Hit h = caster.intersect(ray);
    if (!h.valid()) ++misses;
    else if (h.face != face && glm::dot(ray.d, faceNormalUnnormalized(s, h.face)) > 0.f) ++backs;
  }
  if (backs == kRays)
    return "face " + std::to_string(number) + " sees only the backs of faces: it lies inside a solid (buried under "
           "another surface, as a floor under a block), where no light reaches; its row is 0";
  if (misses == kRays)
    return "face " + std::to_string(number) + " faces away from every other face: nothing is in front of it; its "
           "row is 0";
  return "";
}

}  // namespace

void runFormFactors(FilterInput& in, FilterResult& res) {
  const Scene& s = in.scene;
  const uint32_t chosen = chosenFace(in);
  const uint32_t face = originalFace(res, chosen);  // a duplicated face's copy stands for its original
  if (face != chosen)
    res.stats.note("face " + std::to_string(in.faceNumber(chosen)) + " repeats face " + std::to_string(in.faceNumber(face)) +
                   ": computed for it");
  const auto caster = makeEmbreeCaster(s);
  const FormFactorReport rep = formFactorsOfFace(s, *caster, formFactorSettings(in.values), face);
  FormFactorOutput out = formFactorOutput(s, rep, face, in.faceNumber(face));
  res.vertexQuality = std::move(out.vertexF);
  res.faceQuality = std::move(out.faceF);
  res.faceColor = std::move(out.faceColor);
  res.stats.add("face", double(in.faceNumber(face)));
  res.stats.add("row_sum", rep.rowSum);
  res.stats.add("lost", rep.escaped);
  res.stats.add("max_reciprocity_error", rep.maxReciprocityError);
  res.stats.add("seconds", rep.seconds);
  res.stats.note(out.summary);
  if (!(rep.rowSum > 0.0))
    if (const std::string why = emptyRowReason(s, *caster, face, in.faceNumber(face)); !why.empty()) res.stats.note(why);
  if (const std::string w = cutShortWarning(rep.pairsCutShort); !w.empty()) res.stats.warn(w);
  if (const auto w = narrowPatchWarning(s, narrowPatch(s, face, sceneScale(s).rayEpsilon), "its form factors"))
    res.stats.warn(*w);
}

// The hemicube of the chosen face as pictures; the faces take the pictures'
// colours and the hemicube's F_ij (gi/hemicube_view.h).
void runHemicube(FilterInput& in, FilterResult& res) {
  const Scene& s = in.scene;
  const ParamValues& v = in.values;
  const uint32_t chosen = chosenFace(in);
  const uint32_t face = originalFace(res, chosen);  // a duplicated face's copy stands for its original
  if (face != chosen)
    res.stats.note("face " + std::to_string(in.faceNumber(chosen)) + " repeats face " + std::to_string(in.faceNumber(face)) +
                   ": computed for it");
  if (!usableFaceMask(s)[face]) throw std::invalid_argument("face " + std::to_string(in.faceNumber(face)) + " is degenerate");
  const Timer timer;
  const auto caster = makeEmbreeCaster(s);
  HemicubeView hv = hemicubeView(s, *caster, face, v.getInt("hemicube_resolution"), v.getInt("nusselt_resolution"));
  const HemicubeCells& c = hv.cells;
  res.faceQuality.assign(s.faceCount(), 0.f);
  res.faceColor.resize(s.faceCount());
  double rowSum = 0, nusseltSum = 0, maxDiff = 0;
  size_t seen = 0;
  for (size_t j = 0; j < s.faceCount(); ++j) {
    res.faceQuality[j] = float(c.F[j]);  // as the form-factor row stores it
    res.faceColor[j] = j == face ? Rgb8{255, 255, 255} : patchColor(uint32_t(j));
    rowSum += c.F[j];
    nusseltSum += hv.nusseltF[j];
    maxDiff = std::max(maxDiff, std::fabs(hv.nusseltF[j] - c.F[j]));
    seen += c.F[j] > 0;
  }
  // Per vertex, the area-weighted mean of the incident faces' F (as the form-factor filter writes it).
  std::vector<glm::vec3> F3(s.faceCount());
  for (size_t j = 0; j < F3.size(); ++j) F3[j] = glm::vec3(res.faceQuality[j]);
  for (const glm::vec3& x : faceToVertex(s, F3)) res.vertexQuality.push_back(x.x);
  const std::string path = v.getString("image_path");
  const std::string stem = imageStem(path);
  auto add = [&](const char* name, Image&& img, const std::string& p, double fovDeg) {
    FilterImage fi;
    fi.name = name;
    fi.image = std::move(img);
    fi.exposure = 1.f;  // the colours are the pictures' own
    fi.camera = Camera::lookAt(glm::dvec3(c.eye), glm::dvec3(c.eye + c.n), glm::dvec3(c.b), fovDeg, fi.image.width,
                               fi.image.height);
    fi.path = path.empty() ? "" : p;
    res.images.push_back(std::move(fi));
  };
  const double crossFov = 2.0 * std::atan(2.0) * 180.0 / M_PI;  // the cross spans +-2 in the top face's plane
  add("Hemicube cells by patch", std::move(hv.byPatch), path, crossFov);
  add("Hemicube delta form factors", std::move(hv.deltaF), stem + "_dff.png", crossFov);
  add("Nusselt disk", std::move(hv.nusselt), stem + "_nusselt.png", 90.0);
  res.stats.add("face", double(in.faceNumber(face)));
  res.stats.add("row_sum", rowSum);
  res.stats.add("lost", c.lost);
  res.stats.add("cells_dF_sum", c.total);
  res.stats.add("nusselt_sum", nusseltSum);
  res.stats.add("nusselt_lost", hv.nusseltLost);
  res.stats.add("max_hemicube_nusselt_difference", maxDiff);
  res.stats.add("seconds", timer.seconds());
  char b[400];
  std::snprintf(b, sizeof b,
                "GI: Hemicube of Selected Face: face %llu, %d cells across, %zu patches seen; hemicube row sum %.6f "
                "(cells' dF sum %.6f before normalising), Nusselt disk %d pixels across: covered area / pi %.6f, "
                "largest |F_hemicube - F_Nusselt| %.4g",
                (unsigned long long)in.faceNumber(face), c.resolution, seen, rowSum, c.total, hv.nusseltResolution, nusseltSum, maxDiff);
  res.stats.note(b);
}

// The light-path split (light_paths.h) as four RGB attributes, when asked for.

void runRender(FilterInput& in, FilterResult& res, const Progress& progress) {
  const ParamValues& v = in.values;
  RenderOptions opt = RenderOptions::fromParams(v, in.scene, in.layerCamera ? &*in.layerCamera : nullptr);
  std::string firstPassNote;
  auto perVertex = [&](const char* name, std::vector<glm::vec3>& out) {
    const VertexAttribute* a = in.attribute(name);
    if (!a || a->components != 3 || opt.mode != RenderMode::TwoPass) return;
    out.resize(in.scene.vertexCount());
    for (size_t i = 0; i < out.size() && 3 * i + 2 < a->values.size(); ++i)
      out[i] = {a->values[3 * i], a->values[3 * i + 1], a->values[3 * i + 2]};
  };
  perVertex("Radiosity", opt.firstPassB);
  perVertex("RadiosityDirect", opt.firstPassBdirect);  // the first pass's direct part, if it left one
  // Whether the first pass holds caustics, as it says (first_pass_caustics
  // only for a Radiosity left by another tool): it defaulted to yes, and
  // after radiosity the caustic map was taken out of light without caustics.
  if (const VertexAttribute* c = in.attribute("RadiosityCaustics");
      c && c->components == 1 && !c->values.empty() && opt.mode == RenderMode::TwoPass) {
    // A flag, 0 or 1 at every vertex, as the filters of this suite write it;
    // NaN, -5 or 1e30 were read as "no caustics" in silence (an outside audit).
    const auto bad = std::find_if(c->values.begin(), c->values.end(), [](float x) { return x != 0.f && x != 1.f; });
    if (bad != c->values.end()) {
      char b[64];
      std::snprintf(b, sizeof b, "%g", double(*bad));
      throw std::invalid_argument(
          "the first pass's RadiosityCaustics attribute is neither 0 nor 1 at " +
          std::to_string(std::count_if(c->values.begin(), c->values.end(), [](float x) { return x != 0.f && x != 1.f; })) +
          " vertices (e.g. " + b + "): it is a flag per vertex (1: the first pass holds caustics); remove it, or "
          "rerun the first pass");
    }
    const bool has = std::count_if(c->values.begin(), c->values.end(), [](float x) { return x > 0.5f; }) * 2 >
                     std::ptrdiff_t(c->values.size());
    if (has != opt.firstPassHasCaustics)
      firstPassNote = std::string("the first pass ") + (has ? "holds" : "holds no") +
                      " caustics (its RadiosityCaustics attribute): first_pass_caustics " +
                      (opt.firstPassHasCaustics ? "true" : "false") + " not used";
    opt.firstPassHasCaustics = has;
  }
  const auto caster = makeEmbreeCaster(in.scene);
  RenderResult r = render(in.scene, *caster, opt, progress);
  res.stats = std::move(r.stats);
  if (!firstPassNote.empty()) res.stats.note(firstPassNote);
  FilterImage img;
  img.name = std::string(renderModeName(opt.mode)) + " view";
  img.exposure = imageExposure(r.image, v.getFloat("exposure"), r.seesEmitter);
  img.image = std::move(r.image);
  img.camera = opt.camera;
  img.path = v.getString("image_path");
  res.stats.add("exposure", img.exposure);
  if (opt.vertexRadiance) {
    // What each vertex shows the camera, at the image's exposure.
    for (const glm::vec3& L : r.vertexRadiance) {
      res.vertexQuality.push_back(luminance(L));
      res.vertexColor.push_back(displayMap(L, img.exposure));
    }
    res.attributes.push_back(vectorAttribute("Radiance", r.vertexRadiance));
    if (!r.vertexStdError.empty()) res.attributes.push_back(scalarAttribute("StdError", r.vertexStdError));
  }
  if (opt.mode == RenderMode::PathTraced && r.stdError.size() == img.image.px.size()) {
    // Its error bars as a picture of their own, at the image's exposure: the
    // standard error of each pixel's luminance (grey).
    FilterImage err;
    err.name = "Path traced view, standard error per pixel";
    err.image = Image(img.image.width, img.image.height);
    for (size_t p = 0; p < r.stdError.size(); ++p) err.image.px[p] = glm::vec3(r.stdError[p]);
    err.exposure = img.exposure;
    err.camera = img.camera;
    err.path = img.path.empty() ? "" : stdErrorImagePath(img.path);
    res.images.push_back(std::move(img));
    res.images.push_back(std::move(err));
    return;
  }
  // An earlier path-traced view's error images under this name would
  // describe another image beside this one (an outside audit): removed.
  if (!img.path.empty()) {
    const std::string png = stdErrorImagePath(img.path), pfm = pfmPath(png);
    std::vector<std::string> found;
    for (const std::string& f : {png, pfm})
      if (std::ifstream(f).good()) found.push_back(f);
    if (!found.empty())
      res.stats.note("removes " + (found.size() == 2 ? png + " and .pfm" : found[0]) +
                     ", the error bars of an earlier path-traced view (this mode has none)");
    res.staleFiles = std::move(found);
  }
  res.images.push_back(std::move(img));
}

}  // namespace gi::detail

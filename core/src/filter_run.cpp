#include "gi/filter_run.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <memory>
#include <vector>
#include <stdexcept>
#include <string>

#include "gi/ambient.h"
#include "gi/direct.h"
#include "gi/error_map.h"
#include "gi/filter_files.h"
#include "gi/form_factors.h"
#include "gi/memory_limit.h"
#include "gi/output.h"
#include "gi/pathtrace.h"
#include "gi/photon.h"
#include "gi/radiosity.h"
#include "gi/render.h"
#include "gi/thickness.h"
#include "gi/vertex_order.h"
#include "filter_views.h"
#include "scene_defects.h"

namespace gi {

namespace {

using detail::scalarAttribute;
using detail::vectorAttribute;
using detail::firstPassCausticsAttribute;
using detail::copyDuplicates;
using detail::leaveOutDuplicates;
using detail::overlappingEmittersWarning;
using detail::strayExtentWarning;

// Validation, the scene conventions and the scene report: steps 1 and 2.
void prepare(FilterKind kind, FilterInput& in, FilterResult& res) {
  if (in.scene.faceCount() == 0)
    throw std::invalid_argument(in.scene.vertexCount() == 0
                                    ? "the mesh is empty"
                                    : "the mesh has no faces (a point cloud?): these filters need triangles");
  // Vertex normals come from the triangles in every front end (docs/design.md, "Conventions").
  in.scene.vertexNormals.clear();
  const std::vector<ParamSpec> specs = filterSpecs(kind);
  // MeshLab holds RichFloat and RichAbsPerc values in single precision: the
  // command-line tool's doubles are rounded the same way, so that both front
  // ends compute with the same numbers.
  for (const ParamSpec& p : specs)
    if ((p.type == ParamType::Float || p.type == ParamType::Distance) && in.values.has(p.name))
      in.values.set(p.name, double(float(in.values.getFloat(p.name))));
  const double diagonal = sceneDiagonal(in.scene);
  if (auto err = validate(specs, in.values, diagonal)) throw std::invalid_argument(*err);
  const ParamValues& v = in.values;
  // Vertex colours that display the light an earlier lighting filter left
  // (radiosity, photon mapping, the reference, sky lighting, a view's vertex
  // radiance) are not the surfaces' colours.
  for (const char* shown : kResultAttributes)
    if (in.attrs.vertexColorShows.empty() && in.attribute(shown) && colorsDisplay(shown, in.attrs.vertexColor))
      in.attrs.vertexColorShows = shown;
  if (v.has("reflectance_source"))
    if (auto err = applySceneConventions(in.scene, in.attrs, v, v.has("emitter_source"), &res.setupLog))
      throw std::invalid_argument(*err);
  if (v.has("mirror_layers")) {
    std::string log;
    if (auto err = applyMaterials(in.scene, in.layers, v, &log, &res.setupWarnings)) throw std::invalid_argument(*err);
    res.setupLog += (res.setupLog.empty() ? "" : "; ") + log;
  }
  // After the materials: a mirror's or glass layer's faces take the specular colour.
  if (v.has("reflectance_source"))
    if (auto w = whiteReflectanceWarning(in.scene)) res.setupWarnings.push_back(*w);
  res.report = analyzeScene(in.scene, true, nullptr, &res.sameFaces);  // the pairs for leaveOutDuplicates
  if (res.report.usableFaces() == 0)
    throw std::invalid_argument("the mesh has no usable triangles (" + res.report.summary() + ")");
  if (kind == FilterKind::ErrorMap) res.sameFaces.clear();  // compares values as they are, copies included
  else if (res.report.duplicateFaces) leaveOutDuplicates(in, res);
  if (kind != FilterKind::ErrorMap)
    if (auto w = strayExtentWarning(in.scene, res.report)) res.setupWarnings.push_back(*w);
  if (kind == FilterKind::Radiosity || kind == FilterKind::PhotonMapping || kind == FilterKind::PathTracedReference ||
      kind == FilterKind::RayTracedView)
    if (auto w = overlappingEmittersWarning(in.scene)) res.setupWarnings.push_back(*w);
  // A face turned over shows its black back to what its neighbours light,
  // and the vertices it shares read dark (an outside audit: half a Cornell
  // box's faces turned over left 477 of 1,010 lit vertices below 0.01, with
  // no word).
  if (res.report.misorientedEdges && kind != FilterKind::ErrorMap)
    res.setupWarnings.push_back(std::to_string(res.report.misorientedEdges) +
                                " edges join faces turned opposite ways (the faces are not consistently oriented): "
                                "a face turned over has its back, which is black, towards the light, and the values "
                                "beside it are wrong; re-orient the faces (MeshLab: Normals, Curvatures and "
                                "Orientation > Re-Orient all faces coherently)");
}

std::vector<glm::vec3> vectors(const VertexAttribute* a) {
  std::vector<glm::vec3> v(a ? a->values.size() / 3 : 0);
  for (size_t i = 0; i < v.size(); ++i) v[i] = {a->values[3 * i], a->values[3 * i + 1], a->values[3 * i + 2]};
  return v;
}

// Radiometric output (quality = luminance, colour = display mapping) of the
// linear RGB value the estimate left as an attribute ("Radiosity": what a
// later pass, such as a ray-traced view, reads back from the mesh).
void radiometric(FilterResult& res, const Scene& s, double exposure, const std::string& attribute) {
  const VertexOutput out = radiometricOutput(s, vectors(res.attribute(attribute)), exposure);
  res.vertexQuality = out.quality;
  res.vertexColor = out.displayColors();
  res.stats.add("exposure", out.exposure);
}

void faceRadiometric(FilterResult& res, const std::vector<glm::vec3>& Bface) {
  VertexOutput f;
  f.rgb = Bface;
  f.exposure = float(res.stats.get("exposure", 1.0));
  for (const glm::vec3& b : Bface) f.quality.push_back(luminance(b));
  res.faceQuality = f.quality;
  res.faceColor = f.displayColors();
}

// Multiplies sRGB vertex colours (white where the mesh has none) by a factor in linear light.
std::vector<Rgb8> multiplyColors(const std::vector<glm::u8vec3>& colors, const std::vector<float>& factor) {
  std::vector<Rgb8> out(factor.size());
  for (size_t i = 0; i < factor.size(); ++i) {
    const glm::u8vec3 c = i < colors.size() ? colors[i] : glm::u8vec3(255);
    const float f = std::isfinite(factor[i]) ? factor[i] : 0.f;
    out[i] = displayMap(srgb8ToLinear(c.r, c.g, c.b) * f, 1.f);
  }
  return out;
}

void runAmbient(FilterKind kind, FilterInput& in, FilterResult& res, const Progress& progress) {
  const AmbientMode mode = kind == FilterKind::AmbientOcclusion    ? AmbientMode::Occlusion
                           : kind == FilterKind::AmbientObscurance ? AmbientMode::Obscurance
                                                                   : AmbientMode::Sky;
  const ParamValues& v = in.values;
  AmbientOptions opt = AmbientOptions::fromParams(mode, v);
  opt.vertices = in.vertices;
  // Large meshes are computed with their vertices in a spatial order
  // (gi/vertex_order.h): each vertex keeps its rays, keyed by its index in
  // the mesh, and the results go back in the mesh's order.
  const Timer ordering;
  const VertexOrder order = spatialVertexOrder(in.scene, kSpatialOrderFrom);
  Scene reordered;
  if (!order.identity()) {
    reordered = reorderVertices(in.scene, order);
    opt.vertices.ids = order.meshIndex;
  }
  const Scene& scene = order.identity() ? in.scene : reordered;
  const double orderSeconds = ordering.seconds();
  const Timer bvh;
  const auto caster = makeEmbreeCaster(scene, opt.batch);
  const double bvhSeconds = bvh.seconds();
  AmbientResult r = computeAmbient(scene, *caster, opt, progress);
  if (auto near = detail::nearSurfacesWarning(scene, *caster)) r.stats.warn(*near);
  if (!order.identity()) {
    const Timer back;
    r.value = toMeshOrder(r.value, order);
    r.stdError = toMeshOrder(r.stdError, order);
    r.rays = toMeshOrder(r.rays, order);
    r.rgb = toMeshOrder(r.rgb, order);
    r.bentNormal = toMeshOrder(r.bentNormal, order);
    for (auto& [key, value] : r.stats.numbers)
      if (key == "seconds") value += orderSeconds + back.seconds();  // the filter's time includes the reordering
    r.stats.add("vertex_order_seconds", orderSeconds);
  }
  res.stats = std::move(r.stats);
  res.stats.add("bvh_seconds", bvhSeconds);  // building the ray caster, not in "seconds"
  if (mode == AmbientMode::Sky) {
    res.attributes.push_back(vectorAttribute("Irradiance", r.rgb));
  } else {
    res.vertexQuality = r.value;
    if (opt.bentNormals) res.attributes.push_back(vectorAttribute("BentNormal", r.bentNormal));
  }
  res.attributes.push_back(scalarAttribute("StdError", r.stdError));
}

void outputAmbient(FilterKind kind, FilterInput& in, FilterResult& res) {
  const ParamValues& v = in.values;
  if (kind == FilterKind::SkyLighting) return radiometric(res, in.scene, v.getFloat("exposure"), "Irradiance");
  const AOColorMapping mapping =
      kind == FilterKind::AmbientOcclusion ? kAOColorMappings.get(v, "color_mapping") : AOColorMapping::Grey;
  if (mapping == AOColorMapping::Grey) res.vertexColor = greyColors(res.vertexQuality);
  else if (mapping == AOColorMapping::MultiplyColor) res.vertexColor = multiplyColors(in.attrs.vertexColor, res.vertexQuality);
  // Greys painted by the result are no reflectance for a later lighting
  // filter: the value as an attribute marks them (kResultAttributes,
  // colorsDisplay). 'Multiply colour' leaves the surface's colours, darkened
  // as asked: a later filter's reflectance, as any colours.
  if (mapping == AOColorMapping::Grey)
    res.attributes.push_back(scalarAttribute(
        kind == FilterKind::AmbientOcclusion ? "AmbientOcclusion" : "AmbientObscurance", res.vertexQuality));
  if (const VertexAttribute* bent = res.attribute("BentNormal"); bent && v.getBool("bent_normals_to_vertex_normals"))
    res.vertexNormal = vectors(bent);
}

// Values divided by the q-quantile of the positive ones (a display scale
// that one outlier cannot wash out); unchanged if none is positive.
std::vector<float> relativeToPercentile(const std::vector<float>& v, double q) {
  std::vector<float> pos;
  for (float x : v)
    if (std::isfinite(x) && x > 0.f) pos.push_back(x);
  if (pos.empty()) return v;
  const size_t k = std::min(pos.size() - 1, size_t(q * double(pos.size())));
  std::nth_element(pos.begin(), pos.begin() + long(k), pos.end());
  std::vector<float> out(v.size());
  for (size_t i = 0; i < v.size(); ++i) out[i] = v[i] / pos[k];
  return out;
}

void runThickness(FilterInput& in, FilterResult& res, const Progress& progress) {
  const auto caster = makeEmbreeCaster(in.scene);
  ThicknessResult r = computeThickness(in.scene, *caster, ThicknessOptions::fromParams(in.values), progress);
  res.stats = std::move(r.stats);
  res.vertexQuality = r.value;
  res.attributes.push_back(scalarAttribute("StdError", r.stdError));
}

void addLightPathAttributes(const LightPathSplit& split, FilterResult& res) {
  if (split.empty()) return;
  res.attributes.push_back(vectorAttribute("Radiosity_emitted", split.emitted));
  res.attributes.push_back(vectorAttribute("Radiosity_direct", split.direct));
  res.attributes.push_back(vectorAttribute("Radiosity_caustic", split.caustic));
  res.attributes.push_back(vectorAttribute("Radiosity_indirect", split.indirect));
}

// The vertex selection (traced_selected), 0/1 per vertex; an error sentence
// when no vertex is selected.
std::shared_ptr<const std::vector<uint8_t>> selectedVertices(const FilterInput& in) {
  const std::vector<uint8_t>& sel = in.attrs.vertexSelected;
  const size_t nv = in.scene.vertexCount();
  if (sel.size() != nv || std::none_of(sel.begin(), sel.end(), [](uint8_t x) { return x != 0; }))
    throw std::invalid_argument(
        "traced_selected is on but no vertex is selected (MeshLab: select vertices first, e.g. Filters > Selection; "
        "a PLY file: bit 0x20 of the vertex property 'flags'); turn traced_selected off to trace all vertices");
  auto out = std::make_shared<std::vector<uint8_t>>(nv);
  for (size_t v = 0; v < nv; ++v) (*out)[v] = sel[v] ? 1 : 0;
  return out;
}

void runReference(FilterInput& in, FilterResult& res, const Progress& progress) {
  const auto caster = makeEmbreeCaster(in.scene);
  PathTraceOptions opt = PathTraceOptions::fromParams(in.values, in.scene.origin);
  opt.vertices = in.vertices;
  if (opt.tracedSelected) opt.selectedVertices = selectedVertices(in);
  PathTraceResult r = pathTrace(in.scene, *caster, opt, progress);
  if (auto near = detail::nearSurfacesWarning(in.scene, *caster)) r.stats.warn(*near);
  res.stats = std::move(r.stats);
  res.attributes.push_back(vectorAttribute("Radiosity", r.B));
  res.attributes.push_back(firstPassCausticsAttribute(in.scene.vertexCount(), true));
  res.attributes.push_back(vectorAttribute("Irradiance", r.H));
  res.attributes.push_back(scalarAttribute("StdError", r.stdError));
  res.attributes.push_back(scalarAttribute("StdErrorH", r.stdErrorH));
  res.attributes.push_back(scalarAttribute("Paths", std::vector<float>(r.samples.begin(), r.samples.end())));
  // Every run marks its traced vertices (a whole run's too: a partial run's
  // mark, left on the mesh, hid all but its vertices from a later error map
  // of a whole reference; a review).
  res.attributes.push_back(scalarAttribute(kReferenceTracedAttribute, std::vector<float>(r.traced.begin(), r.traced.end())));
  // The same value and error bar under names no other filter writes: they
  // stay on the mesh while a method under test overwrites quality, Radiosity
  // and StdError, for 'GI: Error Map' to compare with.
  std::vector<float> Y(r.B.size());
  for (size_t i = 0; i < Y.size(); ++i) Y[i] = luminance(r.B[i]);
  res.attributes.push_back(scalarAttribute("Reference", Y));
  res.attributes.push_back(scalarAttribute("ReferenceStdError", r.stdError));
  addLightPathAttributes(r.split, res);
}

void runRadiosity(FilterInput& in, FilterResult& res, const Progress& progress) {
  RadiosityOptions opt = RadiosityOptions::fromParams(in.values);
  opt.vertices = in.vertices;
  // A budget beyond the memory available would let the form-factor matrix
  // grow until the kernel ends the process: the available memory is the budget.
  const double availableMB = double(availableMemoryBytes()) / 1048576.0;
  const bool capped = availableMB > 0 && opt.memoryBudgetMB > availableMB;
  const double askedMB = opt.memoryBudgetMB;
  if (capped) opt.memoryBudgetMB = std::floor(availableMB);
  const int share = memoryShare();
  const std::string lowered = "memory_budget_mb = " + std::to_string(int64_t(askedMB)) + " exceeds the " +
                              std::to_string(int64_t(opt.memoryBudgetMB)) + " MB of memory available" +
                              (share > 1 ? " to each of the " + std::to_string(share) + " ranks on this machine" : "") +
                              ", so the budget was " + std::to_string(int64_t(opt.memoryBudgetMB)) + " MB";
  RadiosityResult r;
  try {
    if (opt.refine) {
      AdaptiveRadiosity ar = solveRadiosityAdaptive(in.scene, opt, progress);
      r = std::move(ar.result);
      res.refined = std::move(ar.mesh);
    } else {
      checkRadiosityMemory(in.scene.faceCount(), opt);  // before the ray-casting structure is built
      const auto caster = makeEmbreeCaster(in.scene);
      r = solveRadiosity(in.scene, *caster, opt, progress);
      if (auto near = detail::nearSurfacesWarning(in.scene, *caster)) r.stats.warn(*near);
    }
  } catch (const std::invalid_argument& e) {
    if (!capped) throw;
    throw std::invalid_argument(lowered + ": " + e.what());  // raising the budget would not help
  }
  res.stats = std::move(r.stats);
  // The plan follows the budget (the form-factor matrix kept or its rows
  // computed on the fly, the hierarchy's links), so the values may differ
  // from a run on a machine with more memory.
  if (capped) res.stats.warn(lowered + " (the solve's memory plan follows it)");
  res.attributes.push_back(vectorAttribute("Radiosity", r.Bvertex));
  res.attributes.push_back(firstPassCausticsAttribute(r.Bvertex.size(), false));
  // Its direct part, for a two-pass view (as photon mapping leaves it).
  if (r.Bdirect.size() == r.Bvertex.size()) res.attributes.push_back(vectorAttribute("RadiosityDirect", r.Bdirect));
  if (in.values.getBool("face_output")) res.faceRadiometry = std::move(r.B);
  // Course outputs: snapshots as attributes, the residual per step in the log and a CSV.
  for (const RadiosityResult::Snapshot& sn : r.snapshots)
    res.attributes.push_back(vectorAttribute("Radiosity_step_" + std::to_string(sn.step), sn.Bvertex));
  if (!opt.snapshotSteps.empty() || !opt.residualCsv.empty()) res.stats.note(residualLogNote(r));
  if (!opt.residualCsv.empty()) res.files.push_back({opt.residualCsv, residualCsv(r)});
  for (auto& [suffix, text] : r.exports) res.files.push_back({opt.exportSystem + suffix, std::move(text)});
}

// The photons of the maps as a point-cloud layer (photon_layer), in the
// scene's frame: past `cap` points, every k-th photon of the two maps in turn
// (indices floor(j total / cap), so each map keeps its share).
FilterLayer photonLayer(const Scene& s, const PhotonMapContents& maps, size_t cap, RunStats& st) {
  static const Rgb8 kGlobal{255, 140, 20}, kCaustic{40, 110, 255};
  FilterLayer L;
  L.name = "Photons";
  L.mesh.origin = s.origin;
  L.mesh.unit = s.unit;
  const size_t total = maps.global.size() + maps.caustic.size(), n = std::min(total, cap);
  const double powerUnit = s.unit * s.unit;  // flux in world units, as emitted_power_W
  for (size_t j = 0; j < n; ++j) {
    const size_t k = n == total ? j : size_t(double(j) * double(total) / double(n));
    const bool caustic = k >= maps.global.size();
    const Photon& p = caustic ? maps.caustic[k - maps.global.size()] : maps.global[k];
    L.mesh.positions.push_back(p.p);
    L.quality.push_back(float(luminance(p.power) * powerUnit));
    L.color.push_back(caustic ? kCaustic : kGlobal);
    L.normals.push_back(p.normal());
  }
  st.add("photon_layer_points", double(n));
  if (n < total)
    st.note("photon layer: " + std::to_string(n) + " of " + std::to_string(total) +
            " stored photons (evenly subsampled: photon_layer_max)");
  return L;
}

void runPhotonMap(FilterInput& in, FilterResult& res, const Progress& progress) {
  const auto caster = makeEmbreeCaster(in.scene);
  const PhotonOptions opt = PhotonOptions::fromParams(in.values, in.scene.origin);
  const bool layer = in.values.getBool("photon_layer");
  PhotonMapContents maps;
  VertexRadiometry r = computePhotonMap(in.scene, *caster, opt, progress, layer ? &maps : nullptr);
  if (auto near = detail::nearSurfacesWarning(in.scene, *caster)) r.stats.warn(*near);
  res.stats = std::move(r.stats);
  if (layer && opt.progressive)
    res.stats.warn("photon_layer: progressive photon mapping keeps no photon map, so no layer was added");
  else if (layer && maps.global.empty() && maps.caustic.empty())
    res.stats.note("photon layer: no photons were stored, so no layer was added");
  else if (layer)
    res.layers.push_back(photonLayer(in.scene, maps, size_t(in.values.getInt("photon_layer_max")), res.stats));
  else if (in.values.getInt("photon_layer_max") != 1000000)
    res.stats.warn("photon_layer_max is not used: photon_layer is off");
  res.attributes.push_back(vectorAttribute("Radiosity", r.B));
  res.attributes.push_back(firstPassCausticsAttribute(r.B.size(), true));
  radiometric(res, in.scene, in.values.getFloat("exposure"), "Radiosity");
  // Its direct part, for a two-pass view (which then need not estimate it again).
  if (r.Bdirect.size() == r.B.size()) res.attributes.push_back(vectorAttribute("RadiosityDirect", r.Bdirect));
  if (r.stdError.size() == r.B.size()) res.attributes.push_back(scalarAttribute("StdError", r.stdError));
  addLightPathAttributes(r.split, res);
}

// Step 4: every array has the output scene's size and nothing non-finite
// leaves the engine (a NaN in MeshLab's quality breaks its colour ramps). A
// value beyond single precision is no answer, and zeros in its place would
// pass for one (a scene of 1e-18 m under a lamp of 1e12 W/sr came out black
// with exit 0): such a run is refused, the mesh left as it was.
void finish(FilterResult& res, const Scene& out) {
  const size_t nv = out.vertexCount(), nf = out.faceCount();
  auto sized = [](size_t n, size_t want, const char* what) {
    if (n != 0 && n != want) throw std::logic_error(std::string("filter result: wrong number of ") + what);
  };
  sized(res.vertexQuality.size(), nv, "vertex qualities");
  sized(res.vertexColor.size(), nv, "vertex colours");
  sized(res.vertexNormal.size(), nv, "vertex normals");
  sized(res.faceQuality.size(), nf, "face qualities");
  sized(res.faceColor.size(), nf, "face colours");
  size_t bad = 0, values = 0;
  auto clean = [&bad, &values](float& x) {
    ++values;
    if (!std::isfinite(x)) x = 0.f, ++bad;
  };
  for (float& q : res.vertexQuality) clean(q);
  for (float& q : res.faceQuality) clean(q);
  for (glm::vec3& n : res.vertexNormal) clean(n.x), clean(n.y), clean(n.z);
  res.attributes.erase(std::remove_if(res.attributes.begin(), res.attributes.end(),
                                      [](const VertexAttribute& a) { return a.values.empty(); }),
                       res.attributes.end());
  for (VertexAttribute& a : res.attributes) {
    sized(a.values.size(), nv * size_t(a.components), a.name.c_str());
    for (float& x : a.values) clean(x);
  }
  for (FilterLayer& L : res.layers) {
    const size_t n = L.mesh.vertexCount();
    sized(L.quality.size(), n, "layer qualities");
    sized(L.color.size(), n, "layer colours");
    sized(L.normals.size(), n, "layer normals");
    for (float& q : L.quality) clean(q);
    for (glm::vec3& p : L.mesh.positions) clean(p.x), clean(p.y), clean(p.z);
    for (glm::vec3& m : L.normals) clean(m.x), clean(m.y), clean(m.z);
  }
  if (bad)
    throw std::invalid_argument(
        "the result is not finite at " + std::to_string(bad) + " of its " + std::to_string(values) +
        " values (beyond single precision, 3.4e38): a light too strong for the scene's size, or a point light all "
        "but touching a vertex (irradiance grows as the inverse square of the distance); lower the light, move it "
        "off the surface or scale the scene up");
}

}  // namespace

const VertexAttribute* FilterInput::attribute(const std::string& name) const {
  for (const auto& a : attributes)
    if (a.name == name) return &a;
  return nullptr;
}

void writeOutputFiles(const FilterResult& r) { writeOutputFiles(r, nullptr); }

std::string layerPath(const std::string& outputPly, const std::string& layerName) {
  const size_t slash = outputPly.find_last_of('/'), dot = outputPly.find_last_of('.');
  const bool ext = dot != std::string::npos && (slash == std::string::npos || dot > slash);
  std::string name = layerName;
  for (char& c : name)
    if (!std::isalnum(static_cast<unsigned char>(c)) && c != '-' && c != '_') c = '_';
  return (ext ? outputPly.substr(0, dot) : outputPly) + "." + name + ".ply";
}

const VertexAttribute* FilterResult::attribute(const std::string& name) const {
  for (const auto& a : attributes)
    if (a.name == name) return &a;
  return nullptr;
}

std::vector<std::string> FilterResult::logLines(const std::string& title) const {
  return {report.summary() + (setupLog.empty() ? "" : "; " + setupLog), stats.line(title)};
}

void FilterResult::reorder(const std::vector<uint32_t>& vertexOrder, const std::vector<uint32_t>& faceOrder) {
  auto permute = [](auto& a, const std::vector<uint32_t>& order, size_t components) {
    if (a.empty()) return;
    auto b = a;
    for (size_t i = 0; i < order.size(); ++i)
      for (size_t c = 0; c < components; ++c) b[i * components + c] = a[order[i] * components + c];
    a.swap(b);
  };
  permute(vertexQuality, vertexOrder, 1);
  permute(vertexColor, vertexOrder, 1);
  permute(vertexNormal, vertexOrder, 1);
  permute(faceQuality, faceOrder, 1);
  permute(faceColor, faceOrder, 1);
  for (VertexAttribute& a : attributes) permute(a.values, vertexOrder, size_t(a.components));
}

FilterResult prepareFilter(FilterKind kind, FilterInput& in) {
  FilterResult res;
  prepare(kind, in, res);
  return res;
}

FilterResult runFilter(FilterKind kind, FilterInput& in, const Progress& progress) {
  FilterResult res = prepareFilter(kind, in);
  computeFilter(kind, in, res, progress);
  return res;
}

bool splitsVertices(FilterKind kind) {
  switch (kind) {
    case FilterKind::AmbientOcclusion:
    case FilterKind::AmbientObscurance:
    case FilterKind::SkyLighting:
    case FilterKind::PathTracedReference:
    case FilterKind::Radiosity: return true;
    default: return false;
  }
}

void computeFilter(FilterKind kind, FilterInput& in, FilterResult& res, const Progress& progress) {
  estimateFilter(kind, in, res, progress);
  outputFilter(kind, in, res);
}

void estimateFilter(FilterKind kind, FilterInput& in, FilterResult& res, const Progress& progress) {
  in.vertices.check();
  if (!in.vertices.all() && !splitsVertices(kind))
    throw std::invalid_argument("'" + filterDesc(kind).meshlabName +
                                "' computes all vertices together: it cannot be split over processes");
  switch (kind) {
    case FilterKind::AmbientOcclusion:
    case FilterKind::AmbientObscurance:
    case FilterKind::SkyLighting: runAmbient(kind, in, res, progress); break;
    case FilterKind::Thickness: runThickness(in, res, progress); break;
    case FilterKind::FormFactorsOfFace: detail::runFormFactors(in, res); break;
    case FilterKind::PathTracedReference: runReference(in, res, progress); break;
    case FilterKind::Radiosity: runRadiosity(in, res, progress); break;
    case FilterKind::PhotonMapping: runPhotonMap(in, res, progress); break;
    case FilterKind::RayTracedView: detail::runRender(in, res, progress); break;
    case FilterKind::HemicubeOfFace: detail::runHemicube(in, res); break;
    case FilterKind::ErrorMap: computeErrorMap(in, res); break;
  }
  // The conventions' warnings first (they concern the input).
  res.stats.warnings.insert(res.stats.warnings.begin(), res.setupWarnings.begin(), res.setupWarnings.end());
}

void outputFilter(FilterKind kind, FilterInput& in, FilterResult& res) {
  const Scene& out = res.refined ? res.refined->scene : in.scene;
  copyDuplicates(res);  // before the exposure and the colours: they see every vertex's value
  switch (kind) {
    case FilterKind::AmbientOcclusion:
    case FilterKind::AmbientObscurance:
    case FilterKind::SkyLighting: outputAmbient(kind, in, res); break;
    case FilterKind::Thickness:
      res.vertexColor = greyColors(relativeToPercentile(res.vertexQuality, 0.99));
      res.attributes.push_back(scalarAttribute("Thickness", res.vertexQuality));  // marks the colours (kResultAttributes)
      break;
    case FilterKind::PathTracedReference: radiometric(res, out, in.values.getFloat("exposure"), "Radiosity"); break;
    case FilterKind::Radiosity:
      radiometric(res, out, in.values.getFloat("exposure"), "Radiosity");
      if (!res.faceRadiometry.empty()) faceRadiometric(res, res.faceRadiometry);
      break;
    default: break;  // the estimate gave the output already
  }
  copyDuplicates(res);  // the colours made since
  finish(res, out);
}

}  // namespace gi

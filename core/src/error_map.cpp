#include "gi/error_map.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <stdexcept>

#include "gi/pathtrace.h"

namespace gi {

std::vector<ParamSpec> ErrorMapOptions::specs() {
  return {
      {.name = "value", .label = "Value to check",
       .help = "The per-vertex value compared with the reference: 'quality' (the vertex quality every GI filter "
               "writes: W/m^2 for radiosity, photon mapping and the reference) or the name of a per-vertex "
               "attribute a filter left (a vector one such as Radiosity by its luminance, 0.2126 R + 0.7152 G + "
               "0.0722 B).",
       .type = ParamType::String, .defText = kQualityAttribute},
      {.name = "value_error", .label = "Standard error of the value",
       .help = "For a noisy value (photon mapping, a second reference): the attribute holding its standard error "
               "(e.g. StdError), counted in the z-score's denominator sqrt(s_ref^2 + s_value^2). Empty: the value "
               "is taken as exact (radiosity).",
       .type = ParamType::String, .defText = ""},
      {.name = "reference_source", .label = "Reference from",
       .help = "Where the reference comes from: an attribute of this mesh (run 'GI: Path Traced Reference' on the "
               "layer first: it leaves Reference and ReferenceStdError, which the other filters do not overwrite), "
               "or a PLY file of the same mesh (same vertices in the same order, e.g. written by `gi reference`).",
       .type = ParamType::Enum, .def = kReferenceSources.index(ReferenceSource::Attribute),
       .choices = kReferenceSources.choices()},
      {.name = "reference_attribute", .label = "Reference value",
       .help = "The reference's per-vertex value: an attribute name (in the mesh or the file), or 'quality' (in a "
               "file, its vertex quality). Vector attributes are compared by luminance.",
       .type = ParamType::String, .defText = "Reference"},
      {.name = "reference_error", .label = "Reference's standard error",
       .help = "The attribute with the reference's standard error per vertex (the path-traced reference writes "
               "ReferenceStdError; in its own PLY also StdError). Needed for z-scores; empty: none.",
       .type = ParamType::String, .defText = "ReferenceStdError"},
      {.name = "reference_file", .label = "Reference PLY file",
       .help = "With 'Reference from' = PLY file: the file (absolute path, or relative to the working folder; on a "
               "line of a gi batch manifest, to the manifest). It must have the mesh's vertex count.",
       .type = ParamType::String, .defText = ""},
      {.name = "error_measure", .label = "Error written",
       .help = "What goes to vertex quality: the difference value - reference (units of the value), the relative "
               "difference (value - reference) / |reference|, or the "
               "z-score (value - reference) / sqrt(s_ref^2 + s_value^2): about N(0,1) where the value is right, "
               "so |z| > 3 (0.27% of vertices by chance) marks a real error. A difference where the reference is 0 "
               "(relative) or has an error bar of 0 (z-score) is unbounded: written as +-3.4e38, the ramp's ends, "
               "with a warning; where the two agree, 0. A z-score without any error bar (a reference of one path "
               "a vertex) is refused.",
       .type = ParamType::Enum, .def = kErrorMeasures.index(ErrorMeasure::Difference),
       .choices = kErrorMeasures.choices()},
      {.name = "color_range", .label = "Colour range",
       .help = "R of the diverging colour ramp: -R blue, 0 white, +R red (symmetric, so white is always 'no "
               "error'). 0 = automatic: the 99th percentile of |error| (z-scores: 3). The log states it.",
       .type = ParamType::Float, .def = 0.0, .min = 0.0, .max = 1e30},
  };
}

ErrorMapOptions ErrorMapOptions::fromParams(const ParamValues& v) {
  ErrorMapOptions o;
  o.value = v.getString("value");
  o.valueError = v.getString("value_error");
  o.source = kReferenceSources.get(v, "reference_source");
  o.reference = v.getString("reference_attribute");
  o.referenceError = v.getString("reference_error");
  o.file = v.getString("reference_file");
  o.measure = kErrorMeasures.get(v, "error_measure");
  o.colorRange = v.getFloat("color_range");
  return o;
}

Rgb8 divergingColor(double t) {
  // Moreland's cool-warm end points and white in the middle, interpolated in
  // linear RGB (he interpolates in his Msh space; this keeps the ends and the
  // neutral middle, which is what the map is read by).
  static const glm::vec3 cold = srgb8ToLinear(59, 76, 192), mid = srgb8ToLinear(242, 242, 242),
                         warm = srgb8ToLinear(180, 4, 38);
  const float u = float(std::clamp(std::isfinite(t) ? t : 0.0, -1.0, 1.0));
  const glm::vec3 c = u < 0.f ? mid + (cold - mid) * -u : mid + (warm - mid) * u;
  return displayMap(c, 1.f);
}

namespace {

std::string fmt(double x) {
  char b[32];
  std::snprintf(b, sizeof b, "%.4g", x);
  return b;
}

}  // namespace

ErrorMapResult errorMap(const std::vector<float>& value, const std::vector<float>& reference,
                        const std::vector<float>& sigmaRef, const std::vector<float>& sigmaValue,
                        ErrorMeasure measure, double colorRange, const std::vector<float>& traced) {
  const size_t n = value.size();
  if (reference.size() != n || (!sigmaRef.empty() && sigmaRef.size() != n) || (!sigmaValue.empty() && sigmaValue.size() != n) ||
      (!traced.empty() && traced.size() != n))
    throw std::logic_error("error map: arrays of different lengths");
  if (measure == ErrorMeasure::ZScore && sigmaRef.empty() && sigmaValue.empty())
    throw std::invalid_argument("a z-score needs a standard error: name the reference's (reference_error) or the "
                                "value's (value_error)");
  ErrorMapResult out;
  out.error.assign(n, 0.f);
  double sumD2 = 0, sumR2 = 0, sumD = 0, maxAbs = 0, sumZ2 = 0;
  size_t used = 0, notFinite = 0, noBar = 0, beyond3 = 0, zCount = 0, saturated = 0, untraced = 0;
  // A partial reference's untraced vertices hold 0, no value: they were
  // compared as 0 (rms 2.2 on a box whose traced vertices agreed; an outside
  // audit).
  auto isTraced = [&](size_t i) { return traced.empty() || traced[i] > 0.5f; };
  // A difference where the reference is 0 (relative) or both error bars are
  // 0 (z-score): the error is unbounded. It was written as 0, white, "no
  // error", which hid a radiosity light leak into a half the reference sees
  // wholly dark, 0 +- 0 (an outside audit); now the ramp's end, as an error
  // beyond single precision is.
  std::vector<size_t> unbounded;
  // Vertices with no error to map (untraced, not finite, no error bar): 0
  // written, painted grey. White, the ramp's 0, read as a perfect match
  // where nothing was compared (an outside audit).
  std::vector<uint8_t> noData(n, 0);
  for (size_t i = 0; i < n; ++i) {
    const double v = value[i], r = reference[i];
    if (!isTraced(i)) { ++untraced; noData[i] = 1; continue; }
    if (!std::isfinite(v) || !std::isfinite(r)) { ++notFinite; noData[i] = 1; continue; }
    const double d = v - r;
    sumD2 += d * d, sumR2 += r * r, sumD += d, maxAbs = std::max(maxAbs, std::abs(d));
    ++used;
    double e = d;
    if (measure == ErrorMeasure::Relative) {
      if (r == 0.0) {
        if (d != 0.0) unbounded.push_back(i);
        continue;
      }
      e = d / std::abs(r);
    } else if (measure == ErrorMeasure::ZScore) {
      const double sr = sigmaRef.empty() ? 0.0 : sigmaRef[i], sv = sigmaValue.empty() ? 0.0 : sigmaValue[i];
      const double s = std::sqrt(sr * sr + sv * sv);
      if (!std::isfinite(s) || sr < 0.0 || sv < 0.0) {  // a negative error bar is no error bar: no z, 0 written
        ++noBar;
        noData[i] = 1;
        continue;
      }
      if (!(s > 0.0)) {
        if (d != 0.0) unbounded.push_back(i);
        continue;
      }
      e = d / s;
      sumZ2 += e * e, ++zCount, beyond3 += std::abs(e) > 3.0;
    }
    // Beyond single precision (values near 3e38 of opposite signs, or
    // divided by a tiny reference): the largest float of its sign, so that a
    // huge error stays huge instead of becoming a non-finite value written
    // as 0.
    if (std::abs(e) > double(std::numeric_limits<float>::max())) {
      e = std::copysign(double(std::numeric_limits<float>::max()), e);
      ++saturated;
    }
    out.error[i] = float(e);
  }
  // No vertex with a finite value and reference (all NaN, or nothing traced)
  // compares nothing: refused, as the map of 0s with rms 0 read "no error"
  // with exit 0 (an outside audit).
  if (used == 0)
    throw std::invalid_argument(
        "no vertex can be compared: " + std::to_string(notFinite) + " have a value or reference that is not a finite "
        "number" + (untraced ? ", " + std::to_string(untraced) + " were not traced by the reference" : std::string()) +
        "; there is no error to map");
  // With no error bar anywhere (a reference of one path a vertex) the bars
  // are unknown, not 0, and no z-score is defined: refused, as a map of 0s
  // painted every vertex white, "no error", where the values differed (an
  // outside audit; it had warned in the log).
  if (measure == ErrorMeasure::ZScore && zCount == 0 && unbounded.size() + noBar > 0)
    throw std::invalid_argument(
        "no vertex has an error bar (all are 0, negative or missing): no z-score is defined; choose the difference "
        "or the relative error, or give a reference with error bars (more than one path a vertex)");
  const float top = std::numeric_limits<float>::max();
  for (size_t i : unbounded) out.error[i] = value[i] > reference[i] ? top : -top;
  // The colour range: given, or the 99th percentile of |error| (z: 3),
  // without the errors at the float's ends.
  double R = colorRange;
  if (!(R > 0.0)) {
    if (measure == ErrorMeasure::ZScore) {
      R = 3.0;
    } else {
      std::vector<float> a;
      for (float e : out.error)
        if (e != 0.f && std::abs(e) < top) a.push_back(std::abs(e));
      if (!a.empty()) {
        const size_t k = std::min(a.size() - 1, size_t(0.99 * double(a.size())));
        std::nth_element(a.begin(), a.begin() + long(k), a.end());
        R = a[k];
      } else {
        R = 0.0;
      }
    }
  }
  // Unbounded errors beside bounded ones that are all 0: any range puts
  // them at the ramp's end (R = 0 painted them white, "no error": an
  // outside review).
  if (!(R > 0.0) && !unbounded.empty()) R = 1.0;
  out.range = R;
  out.color.resize(n);
  for (size_t i = 0; i < n; ++i)
    out.color[i] = noData[i] ? kNoErrorColor : divergingColor(R > 0.0 ? out.error[i] / R : 0.0);

  RunStats& st = out.stats;
  st.add("vertices", double(used));
  st.add("rms_error", used ? std::sqrt(sumD2 / double(used)) : 0.0);
  if (sumR2 > 0 || sumD2 == 0)
    st.add("relative_rms_error", sumR2 > 0 ? std::sqrt(sumD2 / sumR2) : 0.0);
  else
    st.note("no relative RMS error: the reference is 0 at every vertex and the value is not");
  st.add("max_abs_error", maxAbs);
  st.add("mean_error", used ? sumD / double(used) : 0.0);
  if (measure == ErrorMeasure::ZScore) {
    st.add("rms_z", zCount ? std::sqrt(sumZ2 / double(zCount)) : 0.0);
    st.add("fraction_abs_z_above_3", zCount ? double(beyond3) / double(zCount) : 0.0);
    st.note("|z| > 3 at " + std::to_string(beyond3) + " of " + std::to_string(zCount) +
            " vertices (0.27% expected from noise alone)");
  }
  st.add("color_range", R);
  st.note(std::string("quality = ") + kErrorMeasures.logName(measure) +
          (R > 0.0 ? "; colour ramp blue -" + fmt(R) + ", white 0, red +" + fmt(R) + (colorRange > 0 ? "" : " (automatic)")
                   : "; every error is 0: all white"));
  if (saturated)
    st.warn(std::to_string(saturated) + " errors beyond single precision were written as +-" +
            fmt(double(std::numeric_limits<float>::max())));
  if (!unbounded.empty())
    st.warn(std::to_string(unbounded.size()) + " vertices differ from a reference " +
            (measure == ErrorMeasure::Relative ? "of 0" : "whose error bars are 0 (and the value's too)") +
            ": their " + kErrorMeasures.logName(measure) + " is unbounded, written as +-" + fmt(double(top)) +
            " (the colour ramp's ends; left out of the statistics but rms_error and max_abs_error)");
  if (untraced)
    st.note(std::to_string(untraced) + " vertices the reference did not trace (ReferenceTraced 0): no reference "
            "value, left out of every statistic, written as 0 in grey");
  if (used == 0 && untraced)
    st.warn("the reference traced none of the vertices compared: no error is measured");
  if (notFinite)
    st.warn(std::to_string(notFinite) + " vertices where the value or the reference is not a finite number: 0 "
            "written in grey, left out of every statistic");
  if (noBar)
    st.warn(std::to_string(noBar) + " vertices with a negative or non-finite error bar: no z-score, 0 written in grey");
  return out;
}

namespace {

// A per-vertex scalar: a scalar attribute as it is, a vector one (RGB) by its luminance.
std::vector<float> scalarValues(const VertexAttribute& a) {
  if (a.components == 1) return a.values;
  std::vector<float> out(a.values.size() / 3);
  for (size_t i = 0; i < out.size(); ++i)
    out[i] = luminance({a.values[3 * i], a.values[3 * i + 1], a.values[3 * i + 2]});
  return out;
}

std::string names(const std::vector<VertexAttribute>& attrs) {
  std::string s;
  for (const VertexAttribute& a : attrs) s += (s.empty() ? "" : ", ") + a.name;
  return s.empty() ? "none" : s;
}

const VertexAttribute* find(const std::vector<VertexAttribute>& attrs, const std::string& name) {
  for (const VertexAttribute& a : attrs)
    if (a.name == name) return &a;
  return nullptr;
}

// The attribute `name` of `attrs` as per-vertex scalars; `where` names the
// mesh or file in the message when it is missing.
std::vector<float> attributeValues(const std::vector<VertexAttribute>& attrs, const std::string& name,
                                   const std::string& where, const std::string& hint, bool scalarOnly = false) {
  const VertexAttribute* a = find(attrs, name);
  if (!a)
    throw std::invalid_argument(where + " has no per-vertex " +
                                (name == kQualityAttribute ? std::string("quality") : "attribute '" + name + "'") + hint +
                                " (it has: " + names(attrs) + ")");
  if (scalarOnly && a->components != 1)
    throw std::invalid_argument("'" + name + "' is a vector attribute: a standard error must be a scalar");
  return scalarValues(*a);
}

// The file's vertices must be the mesh's, in the same order: equal positions
// up to a float's rounding of the scene's size (files hold floats). The
// vertex count alone let a file with its vertices in another order through,
// and every value was compared with another vertex's.
void checkSameVertices(const Scene& s, const VertexFile& f, const std::string& file) {
  if (f.positions.size() != s.vertexCount()) return;  // a reader without positions
  const double diag = sceneDiagonal(s);
  for (size_t i = 0; i < f.positions.size(); ++i) {
    const glm::dvec3 p = s.toWorld(s.positions[i]);
    // A float's rounding of the coordinates (far from the origin) and of the size.
    const double tol = 1e-5 * diag + 1e-6 * std::max({std::fabs(p.x), std::fabs(p.y), std::fabs(p.z)});
    if (!(glm::length(p - f.positions[i]) <= tol) && std::isfinite(p.x + p.y + p.z))
      throw std::invalid_argument("the reference " + file + "'s vertex " + std::to_string(i) + " lies at (" +
                                  fmt(f.positions[i].x) + ", " + fmt(f.positions[i].y) + ", " + fmt(f.positions[i].z) +
                                  "), the mesh's at (" + fmt(p.x) + ", " + fmt(p.y) + ", " + fmt(p.z) +
                                  "): it must be the same mesh with its vertices in the same order");
  }
}

}  // namespace

void computeErrorMap(const FilterInput& in, FilterResult& res) {
  const ErrorMapOptions o = ErrorMapOptions::fromParams(in.values);
  const size_t nv = in.scene.vertexCount();
  const std::string mesh = "the mesh";
  const std::vector<float> v = attributeValues(in.attributes, o.value, mesh,
                                               o.value == kQualityAttribute ? ": run a filter on it first" : "");
  std::vector<float> sv;
  if (!o.valueError.empty()) sv = attributeValues(in.attributes, o.valueError, mesh, "", true);

  std::vector<float> r, sr, traced;
  std::string from;
  // The reference filter's mark of the vertices it traced (a partial
  // reference), for its own attribute Reference only.
  if (o.source == ReferenceSource::Attribute) {
    if (!o.file.empty()) res.stats.warn("reference_file is not read: the reference comes from an attribute of the mesh");
    // A reference_file given with the attribute source: the message of a
    // missing attribute says the file was not read, and how to read it (it
    // spoke of the attribute only; an outside audit).
    const std::string fileHint =
        o.file.empty() ? std::string()
                       : "; reference_file " + o.file + " is read only with reference_source 'PLY file'";
    r = attributeValues(in.attributes, o.reference, mesh,
                        (o.reference == "Reference" ? ": run 'GI: Path Traced Reference' on this layer first" : "") +
                            fileHint);
    if (!o.referenceError.empty() && find(in.attributes, o.referenceError))
      sr = attributeValues(in.attributes, o.referenceError, mesh, "", true);
    from = "attribute " + o.reference;
    if (const VertexAttribute* t = find(in.attributes, kReferenceTracedAttribute); t && o.reference == "Reference")
      traced = scalarValues(*t);
  } else {
    if (o.file.empty()) throw std::invalid_argument("reference_file is empty: name the reference PLY");
    if (!in.readVertexFile) throw std::invalid_argument("this front end cannot read a reference file");
    VertexFile f;
    try {
      f = in.readVertexFile(o.file);
    } catch (const std::runtime_error& e) {
      throw std::invalid_argument(e.what());
    }
    if (f.vertexCount != nv)
      throw std::invalid_argument("the reference " + o.file + " has " + std::to_string(f.vertexCount) +
                                  " vertices and the mesh " + std::to_string(nv) + ": it must be the same mesh");
    checkSameVertices(in.scene, f, o.file);
    r = attributeValues(f.attributes, o.reference, o.file, "");
    if (!o.referenceError.empty() && find(f.attributes, o.referenceError))
      sr = attributeValues(f.attributes, o.referenceError, o.file, "", true);
    from = o.file + " (" + o.reference + ")";
    if (const VertexAttribute* t = find(f.attributes, kReferenceTracedAttribute); t && o.reference == "Reference")
      traced = scalarValues(*t);
  }
  if (o.measure == ErrorMeasure::ZScore && sr.empty() && sv.empty())
    throw std::invalid_argument("a z-score needs a standard error, and the reference has no attribute '" +
                                o.referenceError + "' (and no value_error is named)");
  if (o.measure == ErrorMeasure::ZScore && sr.empty() && !o.referenceError.empty())
    res.stats.warn("the reference has no attribute '" + o.referenceError +
                   "' (reference_error): the z-scores take the reference as exact, with value_error's bars alone");
  if (o.measure != ErrorMeasure::ZScore && !o.valueError.empty())
    res.stats.warn("value_error is used only by the z-score");
  if (v.size() != nv || r.size() != nv) throw std::logic_error("error map: attribute of the wrong size");
  if (!traced.empty() && traced.size() != nv) traced.clear();
  ErrorMapResult e = errorMap(v, r, sr, sv, o.measure, o.colorRange, traced);
  res.vertexQuality = std::move(e.error);
  res.vertexColor = std::move(e.color);
  res.stats.numbers = std::move(e.stats.numbers);
  res.stats.notes.insert(res.stats.notes.begin(), "value " + o.value + " against the reference " + from +
                                                      (sr.empty() ? "" : ", its error bar " + o.referenceError));
  for (std::string& n : e.stats.notes) res.stats.notes.push_back(std::move(n));
  // The estimate's own warnings (errors beyond single precision, no z-score
  // defined) were dropped here until 5 December 2026.
  for (std::string& w : e.stats.warnings) res.stats.warnings.push_back(std::move(w));
}

}  // namespace gi

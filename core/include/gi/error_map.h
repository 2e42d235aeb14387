// Error map: where a result differs from a reference, per vertex. With v the
// checked value (a filter's quality, or an attribute) and r the reference,
//   difference           e = v - r                      (units of the value)
//   relative difference  e = (v - r) / |r|
//   z-score              z = (v - r) / sqrt(s_r^2 + s_v^2)
// where s_r is the reference's standard error (the path-traced reference's
// ReferenceStdError) and s_v the value's, if it is noisy and has one. For an
// unbiased Monte Carlo reference the central limit theorem makes z close to
// N(0, 1) where v is right, so P(|z| > 3) = 0.27% (Papoulis 1965, Probability,
// Random Variables and Stochastic Processes): many more vertices beyond 3
// show a real error (bias), not noise. Summary over the vertices:
//   RMS = sqrt(mean (v - r)^2), relative RMS = sqrt(sum (v - r)^2 / sum r^2),
//   max |v - r|, the mean difference (bias), and for z-scores the RMS of z and
//   the fraction with |z| > 3.
// The error goes to vertex quality; the colour is a diverging ramp (blue
// below the reference, white on it, red above; Moreland 2009, "Diverging
// Color Maps for Scientific Visualization") over a symmetric range [-R, R].
#pragma once
#include <string>
#include <vector>

#include "gi/color.h"
#include "gi/filter_run.h"
#include "gi/params.h"
#include "gi/run.h"

namespace gi {

enum class ErrorMeasure { Difference, Relative, ZScore };
inline constexpr auto kErrorMeasures = makeEnumTable<ErrorMeasure>({
    {ErrorMeasure::Difference, "Difference (value - reference)", "difference"},
    {ErrorMeasure::Relative, "Relative difference ((value - reference) / |reference|)", "relative difference"},
    {ErrorMeasure::ZScore, "z-score ((value - reference) / standard error)", "z-score"},
});

enum class ReferenceSource { Attribute, File };
inline constexpr auto kReferenceSources = makeEnumTable<ReferenceSource>({
    {ReferenceSource::Attribute, "Attribute of this mesh", "attribute"},
    {ReferenceSource::File, "PLY file", "file"},
});

struct ErrorMapOptions {
  std::string value = kQualityAttribute;  // "quality" or an attribute's name
  std::string valueError;                 // the value's standard error attribute ("": exact)
  ReferenceSource source = ReferenceSource::Attribute;
  std::string reference = "Reference", referenceError = "ReferenceStdError";
  std::string file;  // the reference PLY (source File)
  ErrorMeasure measure = ErrorMeasure::Difference;
  double colorRange = 0.0;  // R; 0 = automatic
  static std::vector<ParamSpec> specs();
  static ErrorMapOptions fromParams(const ParamValues& v);
};

struct ErrorMapResult {
  std::vector<float> error;  // per vertex; 0 where undefined
  std::vector<Rgb8> color;
  double range = 0.0;        // R of the colour ramp
  RunStats stats;
};

// The error of `value` against `reference` (same length); `sigmaRef` and
// `sigmaValue` (empty: none) are their standard errors; `traced` (empty:
// all) is the reference's ReferenceTraced: a vertex it marks 0 has no
// reference value, is left out of every statistic and written as 0 in grey.
// Throws std::invalid_argument for a z-score without any standard error.
ErrorMapResult errorMap(const std::vector<float>& value, const std::vector<float>& reference,
                        const std::vector<float>& sigmaRef, const std::vector<float>& sigmaValue,
                        ErrorMeasure measure, double colorRange, const std::vector<float>& traced = {});
// The colour of a vertex with no error to map: the reference did not trace
// it, its value or reference is not finite, or its error bar is unusable.
inline constexpr Rgb8 kNoErrorColor{128, 128, 128};

// The diverging ramp at t in [-1, 1] (clamped): blue, white at 0, red.
Rgb8 divergingColor(double t);

// The filter 'GI: Error Map' on `in`: finds the value and the reference (an
// attribute of the mesh or the PLY file, read with in.readVertexFile) and
// writes the error, the colours and the summary into `res`. Throws
// std::invalid_argument with one sentence for a missing attribute or file,
// or a file of another vertex count.
void computeErrorMap(const FilterInput& in, FilterResult& res);

}  // namespace gi

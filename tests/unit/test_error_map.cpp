// GI: Error Map (gi/error_map.h): zero against itself, the known error of a
// known perturbation (difference, relative, z-score, the summary), z-scores
// of one path-traced reference against an independent one (another seed)
// spread as N(0, 1), a reference from a PLY file, and a clear error for a
// missing attribute or a file of another vertex count; errors beyond single
// precision written as the largest float.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <limits>
#include <map>
#include <string>

#include "gi/error_map.h"
#include "gi/filter_run.h"
#include "gi/filters.h"
#include "gi/scenes.h"
#include "mesh_io.h"
#include "vertex_file.h"

using namespace gi;

namespace {

FilterInput inputOf(const scenes::SceneFile& sf, FilterKind kind, const std::map<std::string, std::string>& params) {
  FilterInput in;
  in.scene = sf.scene;
  in.attrs = sf.attrs;
  in.layers.push_back({"mesh", 0, sf.scene.faceCount()});
  const auto specs = filterSpecs(kind);
  const double diag = analyzeScene(in.scene).diagonal;
  in.values = defaultValues(specs, diag);
  for (const auto& [k, v] : params) in.values.set(k, parseValue(*findSpec(specs, k), v, diag));
  return in;
}

// What the mesh carries after a filter ran on it: its attributes and its
// quality (as MeshLab's bridge and the PLY files hand them to the next filter).
std::vector<VertexAttribute> leftOnMesh(const FilterResult& r) {
  std::vector<VertexAttribute> a = r.attributes;
  a.push_back({kQualityAttribute, 1, r.vertexQuality});
  return a;
}

FilterResult reference(const scenes::SceneFile& sf, int seed, int samples) {
  FilterInput in = inputOf(sf, FilterKind::PathTracedReference,
                           {{"samples_per_vertex", std::to_string(samples)}, {"seed", std::to_string(seed)}});
  return runFilter(FilterKind::PathTracedReference, in);
}

FilterResult errorMapOf(const scenes::SceneFile& sf, std::vector<VertexAttribute> attrs,
                        const std::map<std::string, std::string>& params) {
  FilterInput in = inputOf(sf, FilterKind::ErrorMap, params);
  in.attributes = std::move(attrs);
  in.readVertexFile = io::readVertexFile;
  return runFilter(FilterKind::ErrorMap, in);
}

std::string messageOf(const std::function<void()>& f) {
  try {
    f();
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "(no error)";
}

}  // namespace

// The reference's quality against its own Reference attribute (the same
// luminance of the same B): every error exactly 0, the colour the ramp's white.
TEST(ErrorMap, ZeroAgainstItself) {
  const auto sf = scenes::cornellBox(150.0);
  const FilterResult ref = reference(sf, 1, 8);
  for (const char* measure : {"0", "1", "2"}) {
    const FilterResult e = errorMapOf(sf, leftOnMesh(ref), {{"error_measure", measure}});
    ASSERT_EQ(e.vertexQuality.size(), sf.scene.vertexCount());
    for (float q : e.vertexQuality) ASSERT_EQ(q, 0.f) << measure;
    const Rgb8 white = divergingColor(0.0);
    for (const Rgb8& c : e.vertexColor) ASSERT_TRUE(c.r == white.r && c.g == white.g && c.b == white.b);
    EXPECT_EQ(e.stats.get("rms_error", -1), 0.0);
    EXPECT_EQ(e.stats.get("max_abs_error", -1), 0.0);
  }
}

// v = r (1 + 0.1 s_i) with s_i = +1 or -1 alternately: the difference is
// 0.1 s_i r_i, the relative difference 0.1 s_i, and with an error bar of
// 0.05 r_i the z-score 2 s_i; RMS = 0.1 sqrt(mean r^2), relative RMS 0.1,
// no |z| > 3. Float rounding of v only: tolerances of a few ulps.
TEST(ErrorMap, KnownPerturbationGivesKnownError) {
  const auto sf = scenes::cornellBox(150.0);
  const size_t n = sf.scene.vertexCount();
  VertexAttribute r{"R", 1, {}}, v{"V", 1, {}}, sr{"SR", 1, {}};
  double sumR2 = 0;
  for (size_t i = 0; i < n; ++i) {
    const float ri = 1.f + float(i % 7);
    const float s = i % 2 ? -1.f : 1.f;
    r.values.push_back(ri);
    v.values.push_back(ri * (1.f + 0.1f * s));
    sr.values.push_back(0.05f * ri);
    sumR2 += double(ri) * ri;
  }
  const std::vector<VertexAttribute> attrs = {r, v, sr};
  const std::map<std::string, std::string> base = {{"value", "V"}, {"reference_attribute", "R"}, {"reference_error", "SR"}};
  auto with = [&](const char* measure) {
    auto p = base;
    p["error_measure"] = measure;
    return errorMapOf(sf, attrs, p);
  };
  const FilterResult d = with("0"), rel = with("1"), z = with("2");
  for (size_t i = 0; i < n; ++i) {
    const double s = i % 2 ? -1.0 : 1.0, ri = r.values[i];
    EXPECT_NEAR(d.vertexQuality[i], 0.1 * s * ri, 1e-5 * ri);
    EXPECT_NEAR(rel.vertexQuality[i], 0.1 * s, 1e-5);
    EXPECT_NEAR(z.vertexQuality[i], 2.0 * s, 1e-4);
  }
  EXPECT_NEAR(d.stats.get("rms_error"), 0.1 * std::sqrt(sumR2 / double(n)), 1e-5);
  EXPECT_NEAR(d.stats.get("relative_rms_error"), 0.1, 1e-5);
  EXPECT_NEAR(d.stats.get("max_abs_error"), 0.7, 1e-5);  // r = 7
  EXPECT_NEAR(z.stats.get("rms_z"), 2.0, 1e-4);
  EXPECT_EQ(z.stats.get("fraction_abs_z_above_3", -1), 0.0);
  EXPECT_EQ(z.stats.get("color_range"), 3.0);  // automatic for z
  // The ramp: blue below the reference, red above, white between.
  EXPECT_GT(z.vertexColor[0].r, z.vertexColor[0].b);
  EXPECT_GT(z.vertexColor[1].b, z.vertexColor[1].r);
  // The log states the range.
  EXPECT_NE(z.logLines("GI: Error Map")[1].find("colour ramp blue -3, white 0, red +3"), std::string::npos);
}

// Two path-traced references with different seeds are independent unbiased
// estimates with honest error bars, so z = (a - b) / sqrt(s_a^2 + s_b^2) is
// close to N(0, 1) at each vertex: E[z^2] = 1 and P(|z| > 3) = 0.0027. With
// n vertices the mean of z^2 has a standard deviation sqrt(2 / n) (0.03 for
// the ~2300 here); error bars estimated from 256 paths each make z a little
// heavier-tailed than normal (Student's t with many degrees of freedom:
// variance 1 + O(1/N)), hence rms_z within 0.1 of 1. The count with |z| > 3
// is binomial with mean 0.0027 n (about 6): a bound of 1.5%, 5 times the
// expected fraction plus 4 binomial standard deviations, holds unless the
// error bars are too small (z's spread too wide). Leaving out the value's own
// error bar (z against s_b only) gives rms_z = sqrt(2), which fails.
TEST(ErrorMap, ZScoresOfIndependentReferencesAreStandardNormal) {
  const auto sf = scenes::cornellBox(40.0);
  const FilterResult a = reference(sf, 11, 256), b = reference(sf, 12, 256);
  std::vector<VertexAttribute> attrs = leftOnMesh(b);  // b is the reference on the mesh
  attrs.push_back({"ValueStdError", 1, a.attribute("StdError")->values});
  attrs.push_back({"Value", 1, a.vertexQuality});
  const FilterResult z = errorMapOf(sf, attrs, {{"value", "Value"}, {"value_error", "ValueStdError"}, {"error_measure", "2"}});
  const double n = z.stats.get("vertices");
  ASSERT_GT(n, 1000.0);
  EXPECT_NEAR(z.stats.get("rms_z"), 1.0, 0.1);
  EXPECT_LT(z.stats.get("fraction_abs_z_above_3"), 0.015);
  // Without the value's error bar the spread is sqrt(2) times wider.
  const FilterResult zRefOnly = errorMapOf(sf, attrs, {{"value", "Value"}, {"error_measure", "2"}});
  EXPECT_GT(zRefOnly.stats.get("rms_z"), 1.25);
}

// A reference from a PLY file (as `gi reference -o` writes it); a file of
// another mesh or a missing attribute is one clear sentence.
TEST(ErrorMap, ReferenceFileAndClearErrors) {
  const auto sf = scenes::cornellBox(150.0);
  const FilterResult ref = reference(sf, 1, 8);
  const auto dir = std::filesystem::temp_directory_path();
  const std::string file = (dir / "gi_errormap_ref.ply").string(), other = (dir / "gi_errormap_other.ply").string();
  io::PlyExtras extras;
  extras.attributes = ref.attributes;
  io::writePly(file, sf.scene, sf.attrs, ref.vertexQuality, ref.vertexColor, extras);
  const auto coarse = scenes::cornellBox(300.0);
  io::writePly(other, coarse.scene, coarse.attrs, std::vector<float>(coarse.scene.vertexCount(), 1.f), {});
  // The file's quality against the mesh's quality: the same values, error 0.
  const FilterResult same = errorMapOf(sf, leftOnMesh(ref), {{"reference_source", "1"}, {"reference_file", file},
                                                             {"reference_attribute", "quality"}, {"error_measure", "2"}});
  for (float q : same.vertexQuality) ASSERT_EQ(q, 0.f);
  EXPECT_NE(same.stats.notes.front().find("gi_errormap_ref.ply"), std::string::npos);

  const std::string mismatch = messageOf([&] {
    errorMapOf(sf, leftOnMesh(ref), {{"reference_source", "1"}, {"reference_file", other}, {"reference_attribute", "quality"}});
  });
  EXPECT_NE(mismatch.find("vertices and the mesh"), std::string::npos) << mismatch;
  EXPECT_EQ(mismatch.find('\n'), std::string::npos);
  const std::string missing = messageOf([&] { errorMapOf(sf, {}, {}); });
  EXPECT_NE(missing.find("no per-vertex quality"), std::string::npos) << missing;
  const std::string noRef = messageOf([&] { errorMapOf(sf, {{kQualityAttribute, 1, ref.vertexQuality}}, {}); });
  EXPECT_NE(noRef.find("'Reference'"), std::string::npos) << noRef;
  EXPECT_NE(noRef.find("GI: Path Traced Reference"), std::string::npos) << noRef;
  // A reference_file given with the attribute source: the message says the
  // file was not read and how to read it (it spoke of the attribute only).
  const std::string fileIgnored = messageOf([&] {
    errorMapOf(sf, {{kQualityAttribute, 1, ref.vertexQuality}}, {{"reference_file", "ref.ply"}});
  });
  EXPECT_NE(fileIgnored.find("reference_file ref.ply is read only with reference_source 'PLY file'"), std::string::npos)
      << fileIgnored;
  const std::string noSigma = messageOf([&] {
    errorMapOf(sf, leftOnMesh(ref), {{"reference_error", "Nothing"}, {"error_measure", "2"}});
  });
  EXPECT_NE(noSigma.find("standard error"), std::string::npos) << noSigma;
  const std::string noFile = messageOf([&] {
    errorMapOf(sf, leftOnMesh(ref), {{"reference_source", "1"}, {"reference_file", (dir / "gi_no_such.ply").string()}});
  });
  EXPECT_NE(noFile.find("no such file"), std::string::npos) << noFile;
  // The same mesh with its vertices in reverse order (faces remapped): the
  // vertex count matches, but every value would meet another vertex's (an
  // outside audit: accepted silently); its positions tell.
  const std::string reversed = (dir / "gi_errormap_reversed.ply").string();
  {
    const size_t nv = sf.scene.vertexCount();
    std::vector<glm::dvec3> pts(nv);
    for (size_t i = 0; i < nv; ++i) pts[nv - 1 - i] = sf.scene.toWorld(sf.scene.positions[i]);
    std::vector<glm::uvec3> tris;
    for (const auto& t : sf.scene.triangles)
      tris.push_back({uint32_t(nv - 1 - t.x), uint32_t(nv - 1 - t.y), uint32_t(nv - 1 - t.z)});
    std::vector<float> q(nv);
    for (size_t i = 0; i < nv; ++i) q[nv - 1 - i] = ref.vertexQuality[i];
    io::writePly(reversed, Scene::fromAbsolute(pts, tris), MeshAttributes{}, q, {});
  }
  const std::string order = messageOf([&] {
    errorMapOf(sf, leftOnMesh(ref), {{"reference_source", "1"}, {"reference_file", reversed}, {"reference_attribute", "quality"}});
  });
  EXPECT_NE(order.find("in the same order"), std::string::npos) << order;
  std::filesystem::remove(file);
  std::filesystem::remove(other);
  std::filesystem::remove(reversed);
}

// Error bars the z-score cannot use are said, not passed over: a
// reference_error the mesh lacks while value_error is named (the z-scores
// then take the value's bars alone: a warning), and negative standard
// errors (no z there, counted with the undefined ones); a reference of 0
// everywhere has no relative RMS error (it read 0, a perfect match).
TEST(ErrorMap, UnusableErrorBarsAreSaid) {
  const auto sf = scenes::cornellBox(300.0);
  const size_t nv = sf.scene.vertexCount();
  std::vector<float> value(nv, 2.f), refv(nv, 1.f), sigma(nv, 0.5f), bad(nv, 0.5f);
  bad[0] = -1.f;
  const std::vector<VertexAttribute> attrs = {{kQualityAttribute, 1, value}, {"Reference", 1, refv},
                                              {"ValueError", 1, sigma}, {"Bad", 1, bad}};
  const FilterResult typo = errorMapOf(sf, attrs, {{"reference_error", "RefStdErrTYPO"}, {"value_error", "ValueError"},
                                                   {"error_measure", "2"}});
  ASSERT_EQ(typo.stats.warnings.size(), 1u);
  EXPECT_NE(typo.stats.warnings[0].find("RefStdErrTYPO"), std::string::npos);
  EXPECT_FLOAT_EQ(typo.vertexQuality[1], 2.f);  // (2 - 1) / 0.5
  const FilterResult negative = errorMapOf(sf, attrs, {{"reference_error", "Bad"}, {"error_measure", "2"}});
  EXPECT_EQ(negative.vertexQuality[0], 0.f);
  EXPECT_EQ(negative.vertexColor[0].r, kNoErrorColor.r);  // no z-score: grey, not white
  EXPECT_EQ(negative.vertexColor[0].g, kNoErrorColor.g);
  EXPECT_FLOAT_EQ(negative.vertexQuality[1], 2.f);
  ASSERT_EQ(negative.stats.warnings.size(), 1u);
  EXPECT_NE(negative.stats.warnings[0].find("1 vertices with a negative or non-finite error bar"), std::string::npos)
      << negative.stats.warnings[0];
  // Error bars of 0 everywhere (a reference of one path a vertex): no
  // z-score is defined anywhere. Refused: a map of 0s painted every vertex
  // white, "no error", where every value differed (an outside audit), and
  // an rms_z of 0 would read as a perfect agreement.
  const std::vector<VertexAttribute> noBars = {{kQualityAttribute, 1, value}, {"Reference", 1, refv},
                                               {"Zero", 1, std::vector<float>(nv, 0.f)}};
  try {
    (void)errorMapOf(sf, noBars, {{"reference_error", "Zero"}, {"error_measure", "2"}});
    ADD_FAILURE() << "a z-score map without error bars was written";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("no z-score is defined"), std::string::npos) << e.what();
  }
  // The same values agreeing exactly: z = 0 / 0 nowhere needed, a map of 0s.
  const std::vector<VertexAttribute> agree = {{kQualityAttribute, 1, refv}, {"Reference", 1, refv},
                                              {"Zero", 1, std::vector<float>(nv, 0.f)}};
  const FilterResult same = errorMapOf(sf, agree, {{"reference_error", "Zero"}, {"error_measure", "2"}});
  EXPECT_EQ(same.vertexQuality[1], 0.f);
  const std::vector<VertexAttribute> zero = {{kQualityAttribute, 1, value}, {"Reference", 1, std::vector<float>(nv, 0.f)}};
  const FilterResult r0 = errorMapOf(sf, zero, {});
  EXPECT_TRUE(std::isnan(r0.stats.get("relative_rms_error", std::nan(""))));
  EXPECT_GT(r0.stats.get("rms_error"), 1.9);
  // No vertex with a finite value: nothing to compare. Refused, as rms 0 and
  // a white map read as a perfect agreement with exit 0 (an outside audit);
  // one finite vertex is enough.
  std::vector<float> nan(nv, std::nanf(""));
  for (ErrorMeasure m : {ErrorMeasure::Difference, ErrorMeasure::Relative, ErrorMeasure::ZScore})
    EXPECT_THROW((void)errorMap(nan, refv, sigma, {}, m, 0.0), std::invalid_argument) << int(m);
  EXPECT_THROW((void)errorMap(value, refv, sigma, {}, ErrorMeasure::Difference, 0.0, std::vector<float>(nv, 0.f)),
               std::invalid_argument);  // nothing traced
  nan[3] = 2.f;
  const ErrorMapResult one = errorMap(nan, refv, sigma, {}, ErrorMeasure::Difference, 0.0);
  EXPECT_EQ(one.stats.get("vertices"), 1.0);
  EXPECT_FLOAT_EQ(one.error[3], 1.f);
}

// An error beyond single precision (values near +-3e38, or a relative error
// over a tiny reference) is written as the largest float of its sign and
// said, never as a non-finite value (which a mesh writer turns into 0: "no
// error"); the colour range stays finite.
TEST(ErrorMap, ErrorsBeyondSinglePrecisionStayHuge) {
  const float big = 3e38f, top = std::numeric_limits<float>::max();
  const std::vector<float> value = {big, -big, 1e10f, 1.f}, ref = {-big, big, 1e-30f, 0.5f};
  const ErrorMapResult d = errorMap(value, ref, {}, {}, ErrorMeasure::Difference, 0.0);
  EXPECT_EQ(d.error[0], top);  // 6e38
  EXPECT_EQ(d.error[1], -top);
  EXPECT_FLOAT_EQ(d.error[2], 1e10f);
  const ErrorMapResult r = errorMap(value, ref, {}, {}, ErrorMeasure::Relative, 0.0);
  EXPECT_FLOAT_EQ(r.error[0], 2.f);  // 6e38 / 3e38
  EXPECT_EQ(r.error[2], top);        // 1e10 / 1e-30
  EXPECT_FLOAT_EQ(r.error[3], 1.f);
  for (const ErrorMapResult* m : {&d, &r}) {
    for (float e : m->error) EXPECT_TRUE(std::isfinite(e));
    EXPECT_TRUE(std::isfinite(m->range) && m->range > 0.0);
    ASSERT_EQ(m->stats.warnings.size(), 1u);
    const std::string said = (m == &d ? "2" : "1") + std::string(" errors beyond single precision");
    EXPECT_EQ(m->stats.warnings[0].rfind(said, 0), 0u) << m->stats.warnings[0];
  }
  const ErrorMapResult fine = errorMap({1.f, 2.f}, {1.5f, 1.f}, {}, {}, ErrorMeasure::Relative, 0.0);
  EXPECT_TRUE(fine.stats.warnings.empty());
}

// A difference where the reference is 0 (relative error) or where both
// error bars are 0 (z-score) is an unbounded error: written at the ramp's
// end with a warning. It was written as 0, white, which hid radiosity's
// leak into the shadow_leak scene's dark half (the reference 0 +- 0 there,
// radiosity 0.0069 to 0.0207 at 24 vertices; an outside audit). Where the
// two agree it stays 0; a value or reference that is not finite is 0 and
// said too (it was a note).
TEST(ErrorMap, UnboundedErrorsAreShownNotHidden) {
  const float top = std::numeric_limits<float>::max(), nan = std::numeric_limits<float>::quiet_NaN();
  const std::vector<float> value = {0.02f, 0.f, 1.5f, 0.5f, nan}, ref = {0.f, 0.f, 1.f, 1.f, 1.f};
  const std::vector<float> bars = {0.f, 0.f, 0.25f, 0.25f, 0.25f};
  const ErrorMapResult z = errorMap(value, ref, bars, {}, ErrorMeasure::ZScore, 0.0);
  EXPECT_EQ(z.error, (std::vector<float>{top, 0.f, 2.f, -2.f, 0.f}));
  EXPECT_DOUBLE_EQ(z.stats.get("rms_z"), 2.0);  // the bounded ones
  const ErrorMapResult r = errorMap(value, ref, {}, {}, ErrorMeasure::Relative, 0.0);
  EXPECT_EQ(r.error, (std::vector<float>{top, 0.f, 0.5f, -0.5f, 0.f}));
  EXPECT_FLOAT_EQ(float(r.range), 0.5f);  // the automatic range leaves the unbounded out
  for (const ErrorMapResult* m : {&z, &r}) {
    ASSERT_EQ(m->stats.warnings.size(), 2u);
    EXPECT_EQ(m->stats.warnings[0].rfind("1 vertices differ from a reference", 0), 0u) << m->stats.warnings[0];
    EXPECT_EQ(m->stats.warnings[1].rfind("1 vertices where the value or the reference is not a finite", 0), 0u)
        << m->stats.warnings[1];
  }
  // The vertex that could not be compared (NaN) is grey, not white ("no
  // error"), in every measure; the one that agrees exactly is white.
  for (const ErrorMapResult* m : {&z, &r}) {
    EXPECT_EQ(m->color[4].r, kNoErrorColor.r);
    EXPECT_EQ(m->color[4].g, kNoErrorColor.g);
    EXPECT_EQ(m->color[4].b, kNoErrorColor.b);
    const Rgb8 white = divergingColor(0.0);
    EXPECT_EQ(m->color[1].r, white.r);
    EXPECT_EQ(m->color[1].g, white.g);
    EXPECT_NE(m->color[4].r, white.r);
  }
  const Rgb8 red = divergingColor(1.0);  // the ramp's end
  EXPECT_EQ(z.color[0].r, red.r);
  EXPECT_EQ(z.color[0].g, red.g);
  EXPECT_EQ(z.color[0].b, red.b);
  const ErrorMapResult d = errorMap(value, ref, {}, {}, ErrorMeasure::Difference, 0.0);
  EXPECT_FLOAT_EQ(d.error[0], 0.02f);
  ASSERT_EQ(d.stats.warnings.size(), 1u);  // only the NaN
  // The only error unbounded, every other 0: still at the ramp's end, not
  // white (the automatic range was 0).
  const ErrorMapResult lone = errorMap({1.f, 2.f}, {0.f, 2.f}, {}, {}, ErrorMeasure::Relative, 0.0);
  EXPECT_EQ(lone.error[0], top);
  EXPECT_EQ(lone.color[0].r, red.r);
  EXPECT_EQ(lone.color[0].g, red.g);
}

// A partial reference (traced_vertices, traced_selected) holds 0 at the
// vertices it did not trace, marked by ReferenceTraced 0: those have no
// reference value. They were compared as 0 (an outside audit: rms 2.2 and
// 92 of 96 vertices "unbounded" on a box whose traced vertices agreed);
// now left out of every statistic, written as 0 in grey, and counted.
TEST(ErrorMap, PartialReferenceComparesTracedVerticesOnly) {
  const auto sf = scenes::cornellBox(150.0);
  const size_t nv = sf.scene.vertexCount();
  std::vector<float> value(nv, 2.f), ref(nv, 0.f), traced(nv, 0.f), bars(nv, 0.1f);
  size_t nTraced = 0;
  for (size_t i = 0; i < nv; i += 3) ref[i] = 2.f, traced[i] = 1.f, ++nTraced;
  value[0] = 2.5f;  // one traced vertex off by 0.5
  const std::vector<VertexAttribute> attrs = {{kQualityAttribute, 1, value},
                                              {"Reference", 1, ref},
                                              {"ReferenceStdError", 1, bars},
                                              {"ReferenceTraced", 1, traced}};
  for (const char* measure : {"0", "1", "2"}) {
    const FilterResult r = errorMapOf(sf, attrs, {{"error_measure", measure}});
    EXPECT_TRUE(r.stats.warnings.empty()) << measure << ": " << r.stats.warnings.front();
    EXPECT_EQ(r.stats.get("vertices"), double(nTraced)) << measure;
    EXPECT_NEAR(r.stats.get("max_abs_error"), 0.5, 1e-6) << measure;
    EXPECT_NEAR(r.stats.get("rms_error"), 0.5 / std::sqrt(double(nTraced)), 1e-6) << measure;
    bool noted = false;
    for (const std::string& n : r.stats.notes) noted |= n.find(std::to_string(nv - nTraced) + " vertices the reference did not trace") == 0;
    EXPECT_TRUE(noted) << measure;
    for (size_t i = 1; i < nv; ++i) {
      ASSERT_EQ(r.vertexQuality[i], 0.f) << measure << " vertex " << i;
      if (traced[i] == 0.f) {
        ASSERT_EQ(r.vertexColor[i].r, kNoErrorColor.r) << measure << " vertex " << i;
      }
    }
    EXPECT_GT(r.vertexQuality[0], 0.f) << measure;
  }
  // A whole reference marks every vertex it traced (a partial run's mark
  // left on the mesh hid all but its vertices from the map of a later whole
  // reference; a review).
  const FilterResult whole = reference(sf, 1, 2);
  const VertexAttribute* mark = whole.attribute("ReferenceTraced");
  ASSERT_NE(mark, nullptr);
  EXPECT_EQ(std::count(mark->values.begin(), mark->values.end(), 1.f), std::ptrdiff_t(nv));
  // The mark applies to the reference filter's own attribute only.
  std::vector<VertexAttribute> mine = attrs;
  mine[1].name = "MyReference";
  EXPECT_EQ(errorMapOf(sf, mine, {{"reference_attribute", "MyReference"}}).stats.get("vertices"), double(nv));
  // Without the mark every vertex is compared (a reference of the whole mesh).
  const FilterResult all = errorMapOf(sf, {attrs[0], attrs[1], attrs[2]}, {});
  EXPECT_EQ(all.stats.get("vertices"), double(nv));
  EXPECT_GT(all.stats.get("rms_error"), 1.0);
}

// "GI: Hemicube of Selected Face" (gi/hemicube_view.h): the cells' delta form
// factors, their per-patch sums against the form-factor filter's hemicube
// row, the Nusselt disk against the exact point-to-triangle factor, and the
// refusals.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <stdexcept>

#include "gi/filter_run.h"
#include "gi/form_factor_analytic.h"
#include "gi/form_factors.h"
#include "gi/hemicube_view.h"
#include "gi/scenes.h"
#include "filter_input.h"

using namespace gi;

namespace {

// An empty closed box seen from inside, 4 x 4 patches a side: nothing
// occludes anything, so the exact point-to-triangle factor is the truth.
const scenes::SceneFile& box() {
  static const scenes::SceneFile sf = scenes::closedBox(1.0, 4, true);
  return sf;
}

FilterInput input(FilterKind kind, const scenes::SceneFile& sf) { return test::filterInput(kind, sf); }

// The per-patch sums of the cells, in the order the hemicube method adds
// them (faces 0-4, rows, columns), normalised by the sum of all cells.
std::vector<double> cellSums(const HemicubeCells& c, size_t faces) {
  std::vector<double> F(faces, 0.0);
  for (const auto& f : c.faces)
    for (size_t k = 0; k < f.patch.size(); ++k)
      if (f.patch[k] != kNoHit && !f.back[k]) F[f.patch[k]] += f.dF[k];
  for (double& x : F) x /= c.total;
  return F;
}

double rawSum(int res) {
  const auto caster = makeEmbreeCaster(box().scene);
  const HemicubeView v = hemicubeView(box().scene, *caster, 0, res, 16);
  double s = 0;
  for (const auto& f : v.cells.faces)
    for (double d : f.dF) s += d;
  EXPECT_NEAR(s, v.cells.total, 1e-12);
  return s;
}

}  // namespace

// sum dF over the cells is the midpoint rule for the integral of the
// hemicube's kernel, which is 1 (the hemisphere's projected solid angle / pi):
// its error is C h^2 + O(h^4) for cells of side h = 2 / res, so halving h
// divides it by 4 (3.5 to 4.5 allows the h^4 term at res 32 -> 64 -> 128).
// After normalising, the cells and the row (F_j + lost) sum to 1 up to the
// rounding of 3 res^2 double additions (< 3 res^2 eps = 1.1e-11 at res 128)
// and, for the float row, of n floats (n x 2^-24).
TEST(HemicubeView, DeltaFormFactorsSumToOne) {
  const double e32 = rawSum(32) - 1, e64 = rawSum(64) - 1, e128 = rawSum(128) - 1;
  EXPECT_LT(std::fabs(e128), 1e-3) << e128;
  EXPECT_GT(e32 / e64, 3.5);
  EXPECT_LT(e32 / e64, 4.5);
  EXPECT_GT(e64 / e128, 3.5);
  EXPECT_LT(e64 / e128, 4.5);

  const auto caster = makeEmbreeCaster(box().scene);
  const HemicubeView v = hemicubeView(box().scene, *caster, 0, 128, 16);
  double norm = 0;
  for (const auto& f : v.cells.faces)
    for (double d : f.dF) norm += d / v.cells.total;
  EXPECT_NEAR(norm, 1.0, 3.0 * 128 * 128 * std::numeric_limits<double>::epsilon());
  double row = v.cells.lost;
  for (double F : v.cells.F) row += F;
  EXPECT_NEAR(row, 1.0, 3.0 * 128 * 128 * std::numeric_limits<double>::epsilon());
  // A closed room: every cell sees a patch's front. (Before the edge
  // functions of a shared edge were evaluated in one order for both of its
  // triangles, cell centres on diagonals that met them exactly fell through
  // the crack: 21 cells, lost 2.3e-4, here.)
  EXPECT_EQ(v.cells.lost, 0.0);
  for (const auto& f : v.cells.faces)
    for (size_t k = 0; k < f.patch.size(); ++k) EXPECT_TRUE(f.patch[k] != kNoHit && !f.back[k]) << k;
  // The top face's centre cell has the largest dF, h^2 / pi to O(h^4).
  const double h = 2.0 / 128;
  EXPECT_NEAR(hemicubeDeltaFormFactor(128, true, 64, 64), h * h / M_PI, h * h * h * h);
}

// A face that sees nothing loses everything: exactly 1, not more (lost and
// the total sum the same cells in another order: it read
// 1.0000000000000155 at 128 cells across).
TEST(HemicubeView, ALoneFaceLosesAtMostEverything) {
  const Scene s = Scene::fromAbsolute({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}, {{0, 1, 2}});
  const auto caster = makeEmbreeCaster(s);
  for (int res : {16, 128, 200}) {
    const HemicubeView v = hemicubeView(s, *caster, 0, res, 16);
    EXPECT_LE(v.cells.lost, 1.0) << res;
    EXPECT_NEAR(v.cells.lost, 1.0, 1e-12) << res;
    // Nusselt's disk likewise (its pixels' area summed to 1.0034: an outside audit).
    EXPECT_LE(v.nusseltLost, 1.0) << res;
    EXPECT_NEAR(v.nusseltLost, 1.0, 1e-12) << res;
  }
}

// The per-patch sums of the cells are the hemicube method's row (one view at
// the centre), bit for bit, and the filter writes exactly what 'GI: Form
// Factors of Selected Face' writes with the hemicube method.
TEST(HemicubeView, PatchSumsAreTheFormFactorFiltersRow) {
  const Scene& s = box().scene;
  const auto caster = makeEmbreeCaster(s);
  for (uint32_t face : {0u, 37u, 150u}) {
    FormFactors::Settings set;
    set.method = FormFactorMethod::Hemicube;
    set.hemicubeResolution = 64;
    set.hemicubePoints = 1;
    const FormFactorReport rep = formFactorsOfFace(s, *caster, set, face, 0);
    const HemicubeView v = hemicubeView(s, *caster, face, 64, 16);
    const std::vector<double> F = cellSums(v.cells, s.faceCount());
    std::vector<float> rowF(s.faceCount(), 0.f);
    for (size_t k = 0; k < rep.row.j.size(); ++k) rowF[rep.row.j[k]] = rep.row.F[k];
    for (size_t j = 0; j < s.faceCount(); ++j) {
      EXPECT_EQ(float(F[j]), rowF[j]) << "face " << face << " patch " << j;
      EXPECT_EQ(F[j], v.cells.F[j]);
    }
  }
  FilterInput hi = input(FilterKind::HemicubeOfFace, box());
  hi.values.set("face_index", 37);
  hi.values.set("hemicube_resolution", 64);
  hi.values.set("nusselt_resolution", 64);
  const FilterResult hr = runFilter(FilterKind::HemicubeOfFace, hi);
  FilterInput fi = input(FilterKind::FormFactorsOfFace, box());
  fi.values.set("face_index", 37);
  fi.values.set("form_factor_method", int(kFormFactorMethods.index(FormFactorMethod::Hemicube)));
  fi.values.set("hemicube_resolution", 64);
  const FilterResult fr = runFilter(FilterKind::FormFactorsOfFace, fi);
  ASSERT_EQ(hr.faceQuality.size(), fr.faceQuality.size());
  for (size_t j = 0; j < hr.faceQuality.size(); ++j) EXPECT_EQ(hr.faceQuality[j], fr.faceQuality[j]) << j;
}

// Nusselt: the disk area a patch covers / pi is the exact point-to-triangle
// factor from the same point (Lambert's formula; the box is convex, nothing
// occludes). Counting pixel centres errs only in the pixels the region's
// outline crosses, by at most a pixel (h^2) each. The outline of a triangle's
// region is at most three half-ellipses (its edges' great circles projected
// down, each of length <= pi) and an arc of the rim (<= 2 pi): L <= 5 pi, in
// at most 4 pieces; a piece of length l crosses at most 2 l / h + 2 pixels
// (each step of length h crosses at most one vertical and one horizontal grid
// line). So |A / pi - F| <= (2 L / h + 8) h^2 / pi = 10 h + 8 h^2 / pi,
// 0.0098 at 2048 pixels across (h = 2 / 2048). The whole disk's count errs
// only along the rim (L = 2 pi, one piece): (4 pi / h + 2) h^2 / pi.
TEST(HemicubeView, NusseltDiskAreaIsTheFormFactor) {
  const Scene& s = box().scene;
  const auto caster = makeEmbreeCaster(s);
  const int R = 2048;
  const double h = 2.0 / R;
  const uint32_t face = 5;
  const HemicubeView v = hemicubeView(s, *caster, face, 16, R);
  const glm::dvec3 x(v.cells.eye), n(v.cells.n);
  const double tol = 10 * h + 8 * h * h / M_PI;
  double sum = 0, worst = 0;
  for (size_t j = 0; j < s.faceCount(); ++j) {
    if (j == face) continue;
    const auto& t = s.triangles[j];
    const double F = pointToTriangleFormFactor(x, n, glm::dvec3(s.positions[t.x]), glm::dvec3(s.positions[t.y]),
                                               glm::dvec3(s.positions[t.z]));
    EXPECT_NEAR(v.nusseltF[j], F, tol) << "patch " << j;
    worst = std::max(worst, std::fabs(v.nusseltF[j] - F));
    sum += v.nusseltF[j];
  }
  EXPECT_NEAR(sum + v.nusseltLost, 1.0, (4 * M_PI / h + 2) * h * h / M_PI);
  EXPECT_EQ(v.nusseltF[face], 0.0);
  std::printf("Nusselt disk %d px: largest |A/pi - F| %.3g (bound %.3g), covered %.6f\n", R, worst, tol, sum);
}

// The pictures: one pixel per cell, the cell at the top's centre in the
// colour of the patch straight above, the faces of the mesh in the same
// colours, three raster images with the paths derived from image_path.
TEST(HemicubeView, PicturesAndFaceColoursAgree) {
  FilterInput in = input(FilterKind::HemicubeOfFace, box());
  in.values.set("face_index", 0);
  in.values.set("hemicube_resolution", 32);
  in.values.set("nusselt_resolution", 64);
  in.values.set("image_path", std::string("out/hc.png"));
  const FilterResult r = runFilter(FilterKind::HemicubeOfFace, in);
  ASSERT_EQ(r.images.size(), 3u);
  EXPECT_EQ(r.images[0].path, "out/hc.png");
  EXPECT_EQ(r.images[1].path, "out/hc_dff.png");
  EXPECT_EQ(r.images[2].path, "out/hc_nusselt.png");
  EXPECT_EQ(r.images[0].image.width, 64);
  EXPECT_EQ(r.images[2].image.width, 64);
  // The patch the top's central cell shows, by a ray along the normal.
  const Scene& s = box().scene;
  const auto caster = makeEmbreeCaster(s);
  const HemicubeView v = hemicubeView(s, *caster, 0, 32, 16);
  Ray ray;
  ray.o = v.cells.eye;
  ray.d = v.cells.n;
  const Hit hit = caster->intersect(ray);
  ASSERT_TRUE(hit.valid());
  const HemicubeCells::Face& top = v.cells.faces[0];
  // A corner cell (0.5 cell off the axis): the box's 4 x 4 patches put a patch edge on the axis.
  const uint32_t seen = top.patch[size_t(16) * 32 + 16];
  const std::vector<uint8_t> px = toSrgb8(r.images[0].image, r.images[0].exposure);
  const size_t k = (size_t(32 - 16 - 1 + 16) * 64 + size_t(16 + 16)) * 3;  // pixel of cell (16, 16)
  const Rgb8 c = patchColor(seen);
  EXPECT_EQ(px[k], c.r);
  EXPECT_EQ(px[k + 1], c.g);
  EXPECT_EQ(px[k + 2], c.b);
  EXPECT_EQ(r.faceColor[seen].r, c.r);
  EXPECT_EQ(r.faceColor[0].r, 255);
  EXPECT_GT(r.faceQuality[seen], 0.f);
  // The opposite wall is above: the central cell shows a patch facing down.
  EXPECT_LT(glm::dot(faceNormalUnnormalized(s, seen), v.cells.n), 0.f);
  EXPECT_LT(glm::dot(faceNormalUnnormalized(s, hit.face), v.cells.n), 0.f);
}

TEST(HemicubeView, RefusesNoSelectionSeveralAndBadFaces) {
  auto message = [](FilterInput in) {
    try {
      runFilter(FilterKind::HemicubeOfFace, in);
    } catch (const std::invalid_argument& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  FilterInput none = input(FilterKind::HemicubeOfFace, box());
  none.attrs.faceSelected.assign(none.scene.faceCount(), 0);
  EXPECT_NE(message(none).find("select exactly one face (0 are selected"), std::string::npos) << message(none);
  FilterInput two = none;
  two.attrs.faceSelected[3] = two.attrs.faceSelected[9] = 1;
  EXPECT_NE(message(two).find("(2 are selected;"), std::string::npos) << message(two);
  FilterInput one = none;
  one.attrs.faceSelected[9] = 1;
  EXPECT_EQ(runFilter(FilterKind::HemicubeOfFace, one).stats.get("face", -1), 9.0);
  FilterInput beyond = input(FilterKind::HemicubeOfFace, box());
  beyond.values.set("face_index", int(beyond.scene.faceCount()));
  EXPECT_NE(message(beyond).find("beyond the"), std::string::npos) << message(beyond);
  FilterInput degenerate = input(FilterKind::HemicubeOfFace, box());
  degenerate.scene.triangles[4] = {degenerate.scene.triangles[4].x, degenerate.scene.triangles[4].x,
                                   degenerate.scene.triangles[4].y};
  degenerate.values.set("face_index", 4);
  EXPECT_NE(message(degenerate).find("face 4 is degenerate"), std::string::npos) << message(degenerate);
}

// An empty row says why: a Cornell box floor triangle under the short block
// sees only the block's inside (the log said "0 faces reached, lost 1"
// alone; an outside audit), and a lone quad seen from its back faces away
// from everything; an open floor triangle's row is not empty and says
// neither.
TEST(FormFactorsView, AnEmptyRowSaysWhy) {
  const auto noted = [](const FilterResult& r, const std::string& text) {
    for (const std::string& n : r.stats.notes)
      if (n.find(text) != std::string::npos) return true;
    return false;
  };
  auto box = scenes::cornellBox(50.0);
  // A floor face whose centre lies under the short block (x 82-240, z 65-225 mm) and one in the open.
  uint32_t buried = UINT32_MAX, open = UINT32_MAX;
  for (uint32_t f = 0; f < box.scene.faceCount(); ++f) {
    const glm::uvec3& t = box.scene.triangles[f];
    const glm::dvec3 c = (box.scene.toWorld(box.scene.positions[t.x]) + box.scene.toWorld(box.scene.positions[t.y]) +
                          box.scene.toWorld(box.scene.positions[t.z])) / 3.0;
    if (std::fabs(c.y) > 1e-3) continue;
    if (c.x > 120 && c.x < 200 && c.z > 100 && c.z < 190) buried = f;
    if (c.x > 400 && c.z > 400) open = f;
  }
  ASSERT_NE(buried, UINT32_MAX);
  ASSERT_NE(open, UINT32_MAX);
  for (const uint32_t f : {buried, open}) {
    FilterInput in = test::filterInput(FilterKind::FormFactorsOfFace, box);
    in.values.set("face_index", int(f));
    const FilterResult r = runFilter(FilterKind::FormFactorsOfFace, in);
    EXPECT_EQ(noted(r, "sees only the backs of faces"), f == buried) << f << ": row sum " << r.stats.get("row_sum");
  }
  scenes::SceneFile quad;
  quad.scene = Scene::fromAbsolute({{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}}, {{0, 1, 2}, {0, 2, 3}});
  FilterInput in = test::filterInput(FilterKind::FormFactorsOfFace, quad);
  in.values.set("face_index", 0);
  EXPECT_TRUE(noted(runFilter(FilterKind::FormFactorsOfFace, in), "faces away from every other face"));
}

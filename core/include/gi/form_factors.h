// Form factors F_ij (the fraction of the power leaving patch i that arrives
// at patch j) by three methods of the course, row by row:
//  - Monte Carlo: from stratified points on patch i, cosine-weighted rays;
//    F_ij ~ (rays landing on the front of j) / N. Visibility comes free.
//    Origin and direction are independent dimensions of a padded sampler.
//  - Analytic point-to-polygon (Wallace et al. 1989): the exact unoccluded
//    differential-area-to-triangle factor to every patch j in front
//    (Lambert's contour integral), averaged over i by an adaptive midpoint
//    rule (gi/form_factor_analytic.h), times the visibility of one ray per
//    base point to a random point of j; no rays at all in a scene where
//    nothing can block anything (an empty convex room).
//  - Hemicube (Cohen and Greenberg 1985): at the patch centre (or at several
//    points placed where the views differ most), every patch rasterised onto
//    the five faces of a hemicube with a depth buffer; each cell adds its
//    exact delta form factor to the patch it shows.
#pragma once
#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "gi/params.h"
#include "gi/raycaster.h"
#include "gi/scene.h"

namespace gi {

enum class FormFactorMethod { MonteCarlo, Analytic, Hemicube, Auto };
inline constexpr auto kFormFactorMethods = makeEnumTable<FormFactorMethod>({
    {FormFactorMethod::MonteCarlo, "Monte Carlo", "Monte Carlo"},
    {FormFactorMethod::Analytic, "Analytic point-to-polygon", "analytic point-to-polygon"},
    {FormFactorMethod::Hemicube, "Hemicube", "hemicube"},
    {FormFactorMethod::Auto, "Auto", "auto"},
});

// The five views of a hemicube as (forward, right, up) axes in the local
// frame (t, b, n) of the patch: the top face looks along n, the four sides
// along +-t and +-b with n up. A side face's projected y runs from 0 (the
// patch's plane) to 1 (the top face's edge).
inline const glm::vec3 kHemicubeViews[5][3] = {
    {{0, 0, 1}, {1, 0, 0}, {0, 1, 0}},   {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}}, {{-1, 0, 0}, {0, -1, 0}, {0, 0, 1}},
    {{0, 1, 0}, {-1, 0, 0}, {0, 0, 1}}, {{0, -1, 0}, {1, 0, 0}, {0, 0, 1}}};

// The delta form factor of cell (i, j) (column, row from the bottom) of a
// hemicube with `resolution` cells across, at the cell's centre (x, y):
//   top face:  dF = h^2 / (pi (x^2 + y^2 + 1)^2)
//   side face: dF = y h^2 / (pi (x^2 + y^2 + 1)^2),   h = 2 / resolution.
double hemicubeDeltaFormFactor(int resolution, bool top, int i, int j);

// One hemicube view kept whole for study ("GI: Hemicube of Selected Face"):
// per face (0 the top, res x res cells; 1-4 the sides, res x res/2, in the
// order of kHemicubeViews) the patch each cell shows (kNoHit: nothing),
// whether it shows that patch's back, and the cell's delta form factor.
struct HemicubeCells {
  struct Face {
    int width = 0, height = 0;  // cells across, rows (row 0 at the patch's plane for a side)
    std::vector<uint32_t> patch;
    std::vector<uint8_t> back;
    std::vector<double> dF;  // row-major, not normalised
  };
  int resolution = 0;
  glm::vec3 eye{0.f}, t{0.f}, b{0.f}, n{0.f};  // the view point and the local frame (world)
  std::array<Face, 5> faces;
  double total = 0;       // sum of every cell's dF (1 up to the cells' quadrature)
  std::vector<double> F;  // per face of the scene: the sum of its cells' dF / total
  double lost = 0;        // the cells showing nothing or a back, / total
};

// Sparse form-factor row of patch i: F_ij for the patches j its rays reached.
struct FormFactorRow {
  std::vector<uint32_t> j;
  std::vector<float> F;
  float escaped = 0.f;  // fraction of rays that hit nothing (open scenes) or a back face
};

// Computes rows (one per face; unusable faces get empty rows).
class FormFactors {
 public:
  struct Settings {
    FormFactorMethod method = FormFactorMethod::MonteCarlo;
    int raysPerPatch = 1024;
    int analyticPoints = 4;
    int hemicubeResolution = 128;
    uint32_t seed = 0;
    int hemicubePoints = 1;  // hemicube views per patch (1: the centre; more: placed adaptively)
  };
  // Keeps references to the scene and the caster: both must outlive it (a
  // temporary Scene or caster passed directly does not compile, but
  // `*makeEmbreeCaster(s)` written inline still dangles: keep the unique_ptr). Throws std::invalid_argument
  // for settings checkFormFactorSettings refuses or a caster built for
  // another scene.
  FormFactors(const Scene& s, const RayCaster& caster, const Settings& settings);
  FormFactors(const Scene& s, const RayCaster& caster, int raysPerPatch, uint32_t seed)
      : FormFactors(s, caster, Settings{FormFactorMethod::MonteCarlo, raysPerPatch, 4, 128, seed}) {}
  FormFactors(Scene&&, const RayCaster&, const Settings&) = delete;
  FormFactors(const Scene&, RayCaster&&, const Settings&) = delete;
  FormFactors(Scene&&, const RayCaster&, int, uint32_t) = delete;
  FormFactors(const Scene&, RayCaster&&, int, uint32_t) = delete;
  // Computed on the fly, deterministic per (i, seed); i < patchCount(), else
  // std::out_of_range (as area).
  FormFactorRow row(uint32_t i) const;
  // From now on row(i) is the row of the seen part of patch i, a share
  // a[i] of its area (gi/patch_seen.h): F_ij / a_i, the row summing to at
  // most 1 (one hemicube at the centre keeps its point's row), without the
  // patches of share 0 (light landing there leaves).
  void useSeenParts(std::vector<float> a);
  size_t patchCount() const { return area_.size(); }
  double area(uint32_t i) const { return area_.at(i); }
  uint64_t raysCast() const;
  // Analytic: the pairs with F provably below kNegligibleF, taken at the
  // source's centroid with one visibility ray.
  uint64_t farPairsByOnePoint() const;
  // Analytic: the pairs whose refinement wanted more levels or splits than
  // allowed (slivers beyond the allowance): their factors may miss the 1%.
  uint64_t pairsCutShort() const;
  static constexpr double kNegligibleF = 1e-7;
  // The hemicube of patch i seen from its centre, as the hemicube method's
  // one-view row computes it (the same F, bit for bit), with its cells.
  HemicubeCells hemicubeCells(uint32_t i) const;
  FormFactorMethod method() const { return set_.method; }  // never Auto
  int hemicubePoints() const { return set_.hemicubePoints; }
  bool unoccluded() const { return unoccluded_; }            // visibility rays skipped
  // Upper bound of the bytes a full sparse matrix of these rows needs.
  double matrixBytesBound() const;
  // Bytes one thread holds while computing a row (its dense F and, for the
  // hemicube, the face buffers: see hemicubeBufferBytes).
  double rowScratchBytes() const;

 private:
  FormFactorRow monteCarloRow(uint32_t i) const;
  FormFactorRow analyticRow(uint32_t i) const;
  FormFactorRow hemicubeRow(uint32_t i) const;
  double hemicubeAt(uint32_t i, const glm::vec3& c, float phi, std::vector<double>& F, HemicubeCells* keep = nullptr) const;
  const Scene& s_;
  const RayCaster& caster_;
  Settings set_;
  bool unoccluded_ = false;
  float eps_;
  std::vector<double> area_;
  std::vector<glm::vec3> normal_;
  std::vector<uint8_t> ok_;
  std::vector<float> seen_;  // per patch, or empty: whole patches
  mutable std::vector<uint64_t> rays_;        // per patch, for the statistics
  mutable std::vector<uint64_t> farPairs_;  // per patch, for the statistics
  mutable std::vector<uint64_t> cutPairs_;  // per patch, for the statistics
  std::vector<glm::dvec3> centroid_;
  std::vector<double> radius_;
};

// Bytes of the depth, patch and side buffers a hemicube of this resolution
// holds at once (its top face, res^2 cells; the sides have half as many),
// per thread computing rows: 144 MB at resolution 4096.
double hemicubeBufferBytes(int resolution);
// The hemicube's work: every patch's row draws and sums its 3 res^2 cells, so
// the cost grows as patches x res^2 whatever the scene. A sentence to warn
// with when that reaches about 1e11 cell updates (minutes of a core), else
// nothing.
std::optional<std::string> hemicubeCostWarning(size_t patches, int resolution);

// One row for study (the "GI: Form Factors of Selected Face" filter): F from
// face i to every other face, its sum, and the reciprocity A_i F_ij = A_j F_ji
// checked against the rows of the receivers with the largest F_ij.
struct FormFactorReport {
  FormFactorRow row;
  double rowSum = 0, escaped = 0;
  double maxReciprocityError = 0;  // max |A_i F_ij - A_j F_ji| / (A_i F_ij) over the checked pairs
  int reciprocityChecked = 0;
  uint64_t pairsCutShort = 0;  // FormFactors::pairsCutShort of the face's row
  double seconds = 0;
};
// The log's warning where analytic pairs were cut short (none: empty).
std::string cutShortWarning(uint64_t pairs);
// Refuses (std::invalid_argument) settings of the chosen method that leave
// a row without samples: rays_per_patch (Monte Carlo, Auto),
// analytic_points (analytic, Auto) or hemicube_points below 1, a hemicube
// below 4 cells a side.
void checkFormFactorSettings(const FormFactors::Settings& settings);

FormFactorReport formFactorsOfFace(const Scene& s, const RayCaster& caster, const FormFactors::Settings& settings,
                                   uint32_t face, int reciprocityChecks = 16);
std::vector<ParamSpec> formFactorSpecs();
// Patches narrower than the ray offset (their smallest altitude, local
// units): their points lie within the offset of whatever they touch, so the
// rays from them miss the near part of a neighbouring surface (a strip 1e-5
// wide at the foot of an emitting wall, offset 1.4e-5: Monte Carlo 0.16 of
// its factor, analytic 0; an outside audit). Each filter that computes
// per-patch values warns with narrowPatchWarning.
bool narrowPatch(const Scene& s, size_t face, double width);  // smallest altitude below width
size_t narrowPatchCount(const Scene& s);                        // usable faces narrower than the ray offset
std::optional<std::string> narrowPatchWarning(const Scene& s, size_t narrow, const std::string& what);
// The face a "face_index" parameter names: itself if >= 0, else the one
// selected face (throws std::invalid_argument with a sentence otherwise).
uint32_t chosenFace(int faceIndex, const std::vector<uint8_t>& selected, size_t faceCount);
// Settings and face from the filter's parameters.
FormFactors::Settings formFactorSettings(const ParamValues& v);  // method, rays, points, resolution (shared with the radiosity filter)

// True when no face can block the view between two others: every vertex
// lies on or in front of every face's plane (an empty convex room seen from
// inside). Then visibility rays are unnecessary.
bool pairwiseUnoccluded(const Scene& s);

}  // namespace gi

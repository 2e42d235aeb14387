#include "gi_course.h"

#include <cmath>
#include <cstdio>
#include <iostream>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "gi/form_factor_closed.h"
#include "json_text.h"

namespace gi::course {

CLI::App* addFormFactorTable(CLI::App& app, TableArgs& a) {
  CLI::App* t = app.add_subcommand(
      "formfactors-table",
      "form factors of Howell's catalogue in closed form beside the three methods (Monte Carlo, analytic "
      "point-to-polygon, hemicube) with their errors: parallel rectangles, perpendicular rectangles with a common "
      "edge, coaxial disks, for the dimensions given. Exit status 0 when every estimate is within its stated "
      "tolerance, 2 (with one line on stderr naming them) when one is not, 1 for bad input");
  auto dims = [&](const char* name, std::vector<double>& v, const char* help) {
    t->add_option(name, v, help)->expected(3)->delimiter(',');  // checked by the engine (one sentence)
  };
  dims("--parallel", a.parallel, "A,B,C: directly opposed rectangles A x B at distance C (Howell C-11) [1,1,1]");
  dims("--perpendicular", a.perpendicular,
       "W,H,L: from a rectangle of width W to one of height H at 90 degrees, sharing an edge of length L (C-14) "
       "[1,1,1]");
  dims("--disks", a.disks, "RI,RJ,L: from a disk of radius RI to a coaxial parallel one of radius RJ at distance L "
                           "(C-41) [1,1,1]");
  t->add_option("--rays", a.rays, "Monte Carlo rays per source triangle [262144]")->check(CLI::Range(1, 1 << 26));
  t->add_option("--analytic_points", a.analyticPoints, "analytic method's base points per triangle [4]")
      ->check(CLI::Range(1, 4096));
  t->add_option("--hemicube_resolution", a.hemicubeResolution, "hemicube cells across the top face [128]")
      ->check(CLI::Range(8, 4096));
  t->add_option("--hemicube_points", a.hemicubePoints,
                "hemicube views per triangle (1: the classic one view at the centre) [129]")
      ->check(CLI::Range(1, 4096));
  t->add_option("--segments", a.segments, "segments of each disk's polygon [64]")->check(CLI::Range(8, 4096));
  t->add_option("--rings", a.rings, "rings of each disk's polar grid [2]")->check(CLI::Range(1, 256));
  t->add_option("--seed", a.seed, "seed of the Monte Carlo rays [0]");
  t->add_flag("--json", a.json, "print the table as JSON");
  return t;
}

int formFactorTable(const TableArgs& a) {
  const std::vector<ClosedFormScene> cases = {
      parallelRectanglesScene(a.parallel[0], a.parallel[1], a.parallel[2]),
      perpendicularRectanglesScene(a.perpendicular[0], a.perpendicular[1], a.perpendicular[2]),
      coaxialDisksScene(a.disks[0], a.disks[1], a.disks[2], a.rings, a.segments)};
  const ComparisonSettings set{a.rays, a.analyticPoints, a.hemicubeResolution, a.hemicubePoints, a.seed};
  nlohmann::json j = nlohmann::json::array();
  bool allWithin = true;
  std::vector<std::string> outside;  // "analytic for perpendicular w 1, h 1, edge 0.001"
  size_t estimates = 0;
  if (!a.json)
    std::printf("%-44s %-9s  %-22s %-22s %-22s\n", "configuration (source -> target)", "closed", "Monte Carlo",
                "analytic", "hemicube");
  for (const ClosedFormScene& c : cases) {
    const ClosedFormComparison t = compareWithClosedForm(c, set);
    nlohmann::json row = {{"configuration", t.name}, {"closed_form", t.closed}, {"source_triangles", t.sourceFaces},
                          {"target_triangles", t.targetFaces}, {"meshing_error", c.meshError}};
    std::string line;
    char cell[64];
    for (const MethodEstimate& m : t.methods) {
      allWithin = allWithin && m.within();
      ++estimates;
      if (!m.within()) outside.push_back(std::string(kFormFactorMethods.logName(m.method)) + " for " + t.name);
      const bool stated = !std::isnan(m.tolerance);
      row["methods"].push_back({{"method", kFormFactorMethods.logName(m.method)}, {"F", m.F},
                                {"relative_error", m.relError},
                                {"tolerance", stated ? nlohmann::json(m.tolerance) : nlohmann::json(nullptr)},
                                {"within", m.within()}});
      if (stated)
        std::snprintf(cell, sizeof cell, "%.6f %+6.2f%%%s", m.F, 100 * m.relError, m.within() ? "" : " (!)");
      else
        std::snprintf(cell, sizeof cell, "%.6f %+6.2f%%", m.F, 100 * m.relError);
      char padded[80];
      std::snprintf(padded, sizeof padded, " %-22s", cell);
      line += padded;
    }
    j.push_back(row);
    if (!a.json) std::printf("%-44s %.6f %s\n", t.name.c_str(), t.closed, line.c_str());
  }
  if (a.json) {
    std::cout << io::dumpJson(j, 2) << "\n";
  } else {
    std::printf("\nTolerances (relative): Monte Carlo 4 standard errors, at least 0.5%%; analytic 0.5%%; hemicube 2%% "
                "with >= 129 views of >= 128 cells (none stated for fewer); disks add their meshing error "
                "2 (1 - polygon area / disk area) = %.2f%%.%s\n",
                100 * cases[2].meshError, allWithin ? "" : " (!) marks an estimate outside its tolerance.");
  }
  if (!allWithin) {
    std::string which;
    for (size_t i = 0; i < outside.size(); ++i) which += (i ? "; " : "") + outside[i];
    std::cout.flush();
    std::fflush(stdout);  // the table first, then the line that sums it up
    std::fprintf(stderr, "gi: error: %zu of %zu estimates are outside their stated tolerance (exit status 2): %s\n",
                 outside.size(), estimates, which.c_str());
  }
  return allWithin ? 0 : 2;
}

}  // namespace gi::course

// Course commands of `gi` that are not filters: `gi formfactors-table`
// (closed-form form factors beside the three methods, gi/form_factor_closed.h).
#pragma once
#include <CLI/CLI.hpp>

namespace gi::course {

struct TableArgs {
  std::vector<double> parallel{1, 1, 1};       // a, b, distance c
  std::vector<double> perpendicular{1, 1, 1};  // source width w, target height h, common edge l
  std::vector<double> disks{1, 1, 1};          // source radius, target radius, distance
  int rays = 262144, analyticPoints = 4, hemicubeResolution = 128, hemicubePoints = 129, segments = 64, rings = 2;
  unsigned seed = 0;
  bool json = false;
};

CLI::App* addFormFactorTable(CLI::App& app, TableArgs& a);
// Prints the table (or JSON); 0 when every method is within its tolerance, 2
// when one is not (the table marks it, and one line on stderr names them).
int formFactorTable(const TableArgs& a);

}  // namespace gi::course

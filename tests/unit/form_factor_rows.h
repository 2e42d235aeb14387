// Every face's form factor row of a scene (the engine's FormFactors with a
// fresh Embree caster): shared by the form factor and radiosity tests.
#pragma once
#include <cstdint>
#include <vector>

#include "gi/radiosity.h"
#include "gi/raycaster.h"
#include "gi/scene.h"

namespace gi::test {

inline std::vector<FormFactorRow> allRows(const Scene& s, int rays, uint32_t seed = 0,
                                          FormFactorMethod method = FormFactorMethod::MonteCarlo, int points = 4,
                                          int res = 128) {
  auto caster = makeEmbreeCaster(s);
  FormFactors ff(s, *caster, {method, rays, points, res, seed});
  std::vector<FormFactorRow> rows(s.faceCount());
  for (uint32_t i = 0; i < s.faceCount(); ++i) rows[i] = ff.row(i);
  return rows;
}

}  // namespace gi::test

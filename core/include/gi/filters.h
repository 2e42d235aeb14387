// The catalogue of filters: MeshLab name, CLI subcommand and the full
// parameter list in dialog order. MeshLab 2020.09's meshlabserver needs every
// parameter of a filter in a script, in this order: mlxScript writes them.
#pragma once
#include <string>
#include <vector>

#include "gi/params.h"

namespace gi {

enum class FilterKind { AmbientOcclusion, AmbientObscurance, SkyLighting, Radiosity, PhotonMapping, PathTracedReference, FormFactorsOfFace };

struct FilterDesc {
  FilterKind kind;
  std::string meshlabName;  // exact filter name (scripts depend on it)
  std::string cliName;      // subcommand of the command-line tool
  std::string summary;      // one line
};

const std::vector<FilterDesc>& allFilters();
const FilterDesc& filterDesc(FilterKind k);
std::vector<ParamSpec> filterSpecs(FilterKind k);

// A complete .mlx script applying the filters with the given values (e.g.
// defaultValues + overrides), distances as absolute values.
struct ScriptStep {
  FilterKind kind;
  ParamValues values;
};
std::string mlxScript(const std::vector<ScriptStep>& steps, double diagonal);

}  // namespace gi

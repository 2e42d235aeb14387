// The catalogue of filters: for each, its MeshLab name, CLI subcommand,
// plugin, description (MeshLab's filterInfo, the CLI's help), what it writes
// and the full parameter list in dialog order. Front ends take every filter
// from here (docs/design.md, "Adding a filter"). MeshLab 2020.09's
// meshlabserver needs every parameter of a filter in a script, in this order:
// mlxScript writes them.
#pragma once
#include <string>
#include <vector>

#include "gi/params.h"

namespace gi {

enum class FilterKind {
  AmbientOcclusion,
  AmbientObscurance,
  SkyLighting,
  Thickness,
  Radiosity,
  PhotonMapping,
  PathTracedReference,
  FormFactorsOfFace,
  RayTracedView,
  HemicubeOfFace,
  ErrorMap,
};

// What a filter may change in the mesh (MeshLab's postCondition, the PLY the CLI writes).
enum FilterWrites : unsigned {
  WritesVertexQuality = 1u << 0,
  WritesVertexColor = 1u << 1,
  WritesVertexNormal = 1u << 2,
  WritesFaceQuality = 1u << 3,
  WritesFaceColor = 1u << 4,
  WritesGeometry = 1u << 5,  // the mesh may be refined (new vertices and faces)
  WritesImage = 1u << 6,     // an image (MeshLab: a raster layer with its camera)
  WritesLayer = 1u << 7,     // a mesh layer of its own (photon mapping's photons; a re-run refills it)
};

struct FilterDesc {
  FilterKind kind;
  std::string meshlabName;  // exact filter name (scripts depend on it)
  std::string cliName;      // subcommand of the command-line tool
  std::string plugin;       // the MeshLab plugin that offers it (e.g. "filter_ambient")
  std::string summary;      // one line (CLI help)
  std::string info;         // MeshLab's filterInfo: what it computes and how (HTML)
  unsigned writes = 0;      // FilterWrites bits
};

const std::vector<FilterDesc>& allFilters();
const FilterDesc& filterDesc(FilterKind k);
// The filter whose CLI subcommand or MeshLab name is `name`; nullptr if none.
const FilterDesc* findFilter(const std::string& name);
// Every CLI subcommand of the catalogue, comma-separated (help texts and errors).
std::string cliFilterNames();
// The filters of one plugin, in catalogue order.
std::vector<FilterKind> pluginFilters(const std::string& plugin);
std::vector<ParamSpec> filterSpecs(FilterKind k);

// A complete .mlx script applying the filters with the given values (e.g.
// defaultValues + overrides), distances as absolute values.
struct ScriptStep {
  FilterKind kind;
  ParamValues values;
};
std::string mlxScript(const std::vector<ScriptStep>& steps, double diagonal);

}  // namespace gi

// MeshLab plugin offering the engine's ambient occlusion, obscurance and sky lighting: the filters the catalogue
// (gi/filters.h) lists under "filter_ambient". No algorithm and no filter-specific
// code here: gi::ml::GiFilterPlugin does the MeshLab side for every plugin.
#pragma once
#include "gi_plugin.h"

class FilterAmbientPlugin : public QObject, public gi::ml::GiFilterPlugin {
  Q_OBJECT
  GI_MESHLAB_FILTER_PLUGIN

 public:
  FilterAmbientPlugin() : GiFilterPlugin("filter_ambient") { createActions(this); }
};

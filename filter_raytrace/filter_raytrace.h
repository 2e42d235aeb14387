// MeshLab plugin offering the engine's eye pass (the ray-traced view): the
// filters the catalogue (gi/filters.h) lists under "filter_raytrace". No
// algorithm and no filter-specific code here: gi::ml::GiFilterPlugin does the
// MeshLab side for every plugin.
#pragma once
#include "gi_plugin.h"

class FilterRayTracePlugin : public QObject, public gi::ml::GiFilterPlugin {
  Q_OBJECT
  GI_MESHLAB_FILTER_PLUGIN

 public:
  FilterRayTracePlugin() : GiFilterPlugin("filter_raytrace") { createActions(this); }
};

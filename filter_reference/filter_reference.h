// MeshLab plugin offering the engine's the path-traced reference: the filters the catalogue
// (gi/filters.h) lists under "filter_reference". No algorithm and no filter-specific
// code here: gi::ml::GiFilterPlugin does the MeshLab side for every plugin.
#pragma once
#include "gi_plugin.h"

class FilterReferencePlugin : public QObject, public gi::ml::GiFilterPlugin {
  Q_OBJECT
  GI_MESHLAB_FILTER_PLUGIN

 public:
  FilterReferencePlugin() : GiFilterPlugin("filter_reference") { createActions(this); }
};

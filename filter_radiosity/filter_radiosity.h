// MeshLab plugin offering the engine's radiosity and the form factors of one face: the filters the catalogue
// (gi/filters.h) lists under "filter_radiosity". No algorithm and no filter-specific
// code here: gi::ml::GiFilterPlugin does the MeshLab side for every plugin.
#pragma once
#include "gi_plugin.h"

class FilterRadiosityPlugin : public QObject, public gi::ml::GiFilterPlugin {
  Q_OBJECT
  GI_MESHLAB_FILTER_PLUGIN

 public:
  FilterRadiosityPlugin() : GiFilterPlugin("filter_radiosity") { createActions(this); }
};

// MeshLab plugin offering the engine's photon mapping: the filters the catalogue
// (gi/filters.h) lists under "filter_photonmap". No algorithm and no filter-specific
// code here: gi::ml::GiFilterPlugin does the MeshLab side for every plugin.
#pragma once
#include "gi_plugin.h"

class FilterPhotonMapPlugin : public QObject, public gi::ml::GiFilterPlugin {
  Q_OBJECT
  GI_MESHLAB_FILTER_PLUGIN

 public:
  FilterPhotonMapPlugin() : GiFilterPlugin("filter_photonmap") { createActions(this); }
};

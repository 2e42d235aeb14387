#include "filter_photonmap.h"

MESHLAB_PLUGIN_NAME_EXPORTER(FilterPhotonMapPlugin)

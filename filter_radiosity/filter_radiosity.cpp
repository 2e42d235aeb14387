#include "filter_radiosity.h"

MESHLAB_PLUGIN_NAME_EXPORTER(FilterRadiosityPlugin)

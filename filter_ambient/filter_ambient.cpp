#include "filter_ambient.h"

MESHLAB_PLUGIN_NAME_EXPORTER(FilterAmbientPlugin)

#include "filter_raytrace.h"

MESHLAB_PLUGIN_NAME_EXPORTER(FilterRayTracePlugin)

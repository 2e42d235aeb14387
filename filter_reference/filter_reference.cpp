#include "filter_reference.h"

MESHLAB_PLUGIN_NAME_EXPORTER(FilterReferencePlugin)

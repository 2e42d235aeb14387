// gi_cluster.h for a build without MPI: everything runs in this process.
#include "gi_cluster.h"

namespace gi::cluster {

void start(int*, char***) {}
void stop() {}
int rank() { return 0; }
int size() { return 1; }

void compute(FilterKind kind, FilterInput& in, FilterResult& res, const Progress& progress, const SplitOptions&) {
  computeFilter(kind, in, res, progress);
}

bool abandon() { return true; }

nlohmann::json report() { return nullptr; }

}  // namespace gi::cluster

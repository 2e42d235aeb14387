// gi_cluster.h for a build without MPI: everything runs in this process.
#include "gi_cluster.h"

#include <cstdio>
#include <cstdlib>

namespace gi::cluster {

// Started by mpirun (Open MPI's or a PMI launcher's world of more than one
// process), a build without MPI would run the whole job once per process,
// every copy writing the same files (an outside audit: four full runs and
// exit 0; `gi batch` baked one shard twice at once): refused.
void start(int*, char***) {
  for (const char* name : {"OMPI_COMM_WORLD_SIZE", "PMI_SIZE"}) {
    const char* v = std::getenv(name);
    if (v && std::atol(v) > 1) {
      std::fprintf(stderr, "gi: error: started as one of %s processes (%s), but this gi was built without MPI "
                           "(GI_MPI=OFF): each would compute the whole job; run it once, or build with -DGI_MPI=ON\n",
                   v, name);
      std::exit(1);
    }
  }
}
void stop() {}
int rank() { return 0; }
int size() { return 1; }

void compute(FilterKind kind, FilterInput& in, FilterResult& res, const Progress& progress, const SplitOptions&) {
  computeFilter(kind, in, res, progress);
}

bool abandon() { return true; }

nlohmann::json report() { return nullptr; }

}  // namespace gi::cluster

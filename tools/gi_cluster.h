// How `gi` computes a filter: in this process, or, in a build with the
// GI_MPI option started by mpirun (or srun), split over the MPI ranks. Then
// every rank loads the scene and computes its part of the vertices
// (gi::VertexPart through gi::estimateFilter), rank 0 gathers the parts,
// maps them to the output (gi::outputFilter) and writes the result; the other
// ranks write nothing. Per-vertex random numbers make the result
// bit-identical to one process (README, "Beyond one machine").
// gi_cluster_mpi.cpp implements it with MPI, gi_cluster_local.cpp for one
// process (the build without MPI).
#pragma once
#include <cstdint>
#include <nlohmann/json.hpp>
#include <stdexcept>
#include <string>

#include "gi/filter_run.h"

namespace gi::cluster {

struct SplitOptions {
  bool interleaved = true;  // chunk k to rank k mod N (else one run of chunks per rank)
  uint32_t chunk = 1024;    // vertices per chunk
};

// Starts MPI when this process was started by an MPI launcher; a no-op
// otherwise (a plain `gi` run never initialises MPI).
void start(int* argc, char*** argv);
void stop();
int rank();  // 0 in one process
int size();  // 1 in one process

// computeFilter, split over the ranks when there are several. Every rank
// calls it (or `abandon`) exactly once: a parameter error found on every
// rank is thrown on every rank; a rank whose own work fails makes the others
// throw Quiet.
void compute(FilterKind kind, FilterInput& in, FilterResult& res, const Progress& progress, const SplitOptions& split);

// A rank that fails before reaching `compute` calls this instead, so that
// the ranks waiting there learn of it. Returns whether this rank should
// print the error (one line in all: the lowest failing rank's).
bool abandon();

// Thrown on the ranks whose work succeeded when another rank's failed: exit
// 1 without a message (the failing rank prints it).
struct Quiet : std::runtime_error {
  Quiet() : std::runtime_error("another rank failed") {}
};

// What the split run measured, for the JSON summary: per rank its vertices,
// seconds, rays and peak memory, the slowest against the mean, the gather's
// time and bytes. Null in one process.
nlohmann::json report();

}  // namespace gi::cluster

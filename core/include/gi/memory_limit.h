// How much memory a run may still take, and a clear refusal when a request
// would need more. A run past the machine's memory does not fail cleanly on
// Linux: allocations succeed (overcommit) and the kernel's out-of-memory
// killer ends the process later, MeshLab with every unsaved mesh in it.
// So the filters whose memory the parameters set, not the mesh (photons
// stored per pass, the image's pixels), check their need first: against the
// memory the kernel reports as available to new allocations without
// swapping (MemAvailable, Linux 3.14 on), within the memory control group's
// limit where one is set (a container, a Slurm job): the limit less what the
// group holds beyond its reclaimable file cache, the least over the group
// and its parents (cgroup v2), or the v1 memory controller's figures.
#pragma once
#include <cstddef>
#include <string>

namespace gi {

// Bytes available to this process now; 0 if unknown (not Linux, no /proc).
// Where several processes of one run share the machine (MPI ranks on one
// node, which start together and would each see the whole figure), each
// gets its share.
size_t availableMemoryBytes();

// The processes of this run on this machine, counting this one (default 1).
void shareMemoryWith(int processes);
int memoryShare();
// The threads parallel loops may use now (the arena's and --threads' limit).
int workerThreads();

// The limit a run checks against: `limit` if nonzero (a caller's own
// budget), else availableMemoryBytes() (0: unknown, nothing is checked).
size_t memoryLimitOrAvailable(size_t limit);

// Throws std::invalid_argument, in one sentence, when `bytes` exceeds
// `limit` (0: no check): "<what> needs about X GB, more than the Y GB of
// memory available; <remedy>" (MB or KB for smaller amounts).
void requireMemory(double bytes, size_t limit, const std::string& what, const std::string& remedy);

// "6.4 GB", "12 GB", "75 MB", "74 KB": the amount as the refusals write it.
std::string memoryAmount(double bytes);

}  // namespace gi

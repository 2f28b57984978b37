// Cluster (cluster.hpp): MPI when the build has it (NHI_HAVE_MPI) and the
// process was started by an MPI launcher; one rank otherwise.
#include "cluster.hpp"

#include <algorithm>
#include <climits>
#include <cstdio>
#include <cstdlib>
#include <stdexcept>

#ifdef NHI_HAVE_MPI
#include <mpi.h>
#endif

namespace study {

namespace {

// Started by mpirun (Open MPI) or srun (PMIx / PMI-2)?  *size: the number
// of ranks the launcher says it started (1 when it does not say).
bool launched_by_mpi(int* size) {
  *size = 1;
  for (const char* var : {"OMPI_COMM_WORLD_SIZE", "PMI_SIZE", "SLURM_NTASKS"})
    if (const char* v = std::getenv(var)) {
      *size = std::max(1, std::atoi(v));
      break;
    }
  return std::getenv("OMPI_COMM_WORLD_SIZE") || std::getenv("PMIX_RANK") || std::getenv("PMI_RANK");
}

#ifdef NHI_HAVE_MPI
// Any rank leaving without MPI_Finalize (an error path that returns from main
// or calls exit) takes the whole run down with it, never a hang.
bool g_mpi_open = false;
void abort_if_open() {
  if (g_mpi_open) MPI_Abort(MPI_COMM_WORLD, 1);
}
#endif

}  // namespace

bool built_with_mpi() {
#ifdef NHI_HAVE_MPI
  return true;
#else
  return false;
#endif
}

Cluster& Cluster::get() {
  static Cluster c;
  return c;
}

Cluster::Cluster() {
  int launched_size = 1;
  const bool launched = launched_by_mpi(&launched_size);
#ifdef NHI_HAVE_MPI
  if (!launched) return;
  int provided = 0;
  // Only the main thread calls MPI; worker threads compute cells.
  if (MPI_Init_thread(nullptr, nullptr, MPI_THREAD_FUNNELED, &provided) != MPI_SUCCESS) {
    std::fprintf(stderr, "study: MPI_Init_thread failed\n");
    std::exit(2);
  }
  mpi_ = g_mpi_open = true;
  std::atexit(abort_if_open);
  MPI_Comm_rank(MPI_COMM_WORLD, &rank_);
  MPI_Comm_size(MPI_COMM_WORLD, &size_);
  MPI_Comm node;
  MPI_Comm_split_type(MPI_COMM_WORLD, MPI_COMM_TYPE_SHARED, rank_, MPI_INFO_NULL, &node);
  int local = 0;
  MPI_Comm_rank(node, &local);
  MPI_Comm_free(&node);
  std::vector<int> locals(size_);
  MPI_Allgather(&local, 1, MPI_INT, locals.data(), 1, MPI_INT, MPI_COMM_WORLD);
  leaders_.clear();
  for (int r = 0; r < size_; ++r)
    if (locals[r] == 0) leaders_.push_back(r);
#else
  if (launched && launched_size > 1) {
    std::fprintf(stderr,
                 "study: started as one of %d ranks, but this build has no MPI (install libopenmpi-dev and "
                 "rebuild, or run one process)\n",
                 launched_size);
    std::exit(2);
  }
#endif
}

std::vector<std::string> Cluster::all_gather(const std::string& mine) const {
  if (!mpi_) return {mine};
#ifdef NHI_HAVE_MPI
  if (mine.size() > static_cast<size_t>(INT_MAX)) throw std::runtime_error("study: a rank's results exceed 2 GB");
  const int len = static_cast<int>(mine.size());
  std::vector<int> lens(size_), offsets(size_);
  MPI_Allgather(&len, 1, MPI_INT, lens.data(), 1, MPI_INT, MPI_COMM_WORLD);
  long long total = 0;
  for (int r = 0; r < size_; ++r) {
    offsets[r] = static_cast<int>(total);
    total += lens[r];
    if (total > INT_MAX) throw std::runtime_error("study: gathered results exceed 2 GB");
  }
  std::string all(static_cast<size_t>(total), '\0');
  MPI_Allgatherv(mine.data(), len, MPI_BYTE, all.data(), lens.data(), offsets.data(), MPI_BYTE, MPI_COMM_WORLD);
  std::vector<std::string> out(size_);
  for (int r = 0; r < size_; ++r) out[r] = all.substr(offsets[r], lens[r]);
  return out;
#else
  return {mine};
#endif
}

void Cluster::finalize() {
  if (!mpi_ || finalized_) return;
  finalized_ = true;
#ifdef NHI_HAVE_MPI
  g_mpi_open = false;
  MPI_Finalize();
#endif
}

void Cluster::exit_all(int code) {
  std::fflush(stderr);
  finalize();
  std::exit(code);
}

void Cluster::abort(int code) {
  std::fflush(stderr);
#ifdef NHI_HAVE_MPI
  if (g_mpi_open) {
    g_mpi_open = false;
    MPI_Abort(MPI_COMM_WORLD, code);
  }
#endif
  std::exit(code);
}

}  // namespace study

// Cluster (cluster.hpp): MPI when the build has it (NHI_HAVE_MPI) and the
// process was started by an MPI launcher; one rank otherwise.
#include "cluster.hpp"

#include <algorithm>
#include <climits>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <exception>
#include <stdexcept>

#ifdef NHI_HAVE_MPI
#include <mpi.h>
#endif

namespace study {

namespace {

// Any MPI launcher in the environment: mpirun (Open MPI), srun with PMIx or
// PMI-2, or srun without an MPI plugin (SLURM_STEP_NUM_TASKS > 1: then MPI
// sees one rank per process, and Cluster() refuses to run N copies).
bool launched_by_mpi() {
  return std::getenv("OMPI_COMM_WORLD_SIZE") || std::getenv("PMIX_RANK") || std::getenv("PMI_RANK") ||
         launcher_ranks() > 1;
}

#ifdef NHI_HAVE_MPI
// Any rank leaving without MPI_Finalize (an error path that returns from main
// or calls exit) takes the whole run down with it, never a hang.
bool g_mpi_open = false;
void abort_if_open() {
  if (g_mpi_open) MPI_Abort(MPI_COMM_WORLD, 1);
}
// An uncaught exception on one rank ends every rank (std::terminate alone
// would leave the others waiting in a collective under a launcher that does
// not kill the job).
void terminate_all() {
  std::fprintf(stderr, "study: uncaught exception on one rank; aborting every rank\n");
  std::fflush(stderr);
  if (g_mpi_open) MPI_Abort(MPI_COMM_WORLD, 1);
  std::abort();
}
#endif

}  // namespace

int launcher_ranks() {
  for (const char* var : {"OMPI_COMM_WORLD_SIZE", "PMI_SIZE", "SLURM_STEP_NUM_TASKS"})
    if (const char* v = std::getenv(var)) return std::max(1, std::atoi(v));
  return 1;
}

Cluster& Cluster::get() {
  static Cluster c;
  return c;
}

Cluster::Cluster() {
  const int launched_size = launcher_ranks();
  const bool launched = launched_by_mpi();
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
  std::set_terminate(terminate_all);
  MPI_Comm_rank(MPI_COMM_WORLD, &rank_);
  MPI_Comm_size(MPI_COMM_WORLD, &size_);
  if (launched_size > 1 && size_ != launched_size) {
    // srun without --mpi=pmix, or another MPI's launcher: N one-rank jobs
    // would each run the whole study and race for the output.
    std::fprintf(stderr,
                 "study: the launcher started %d tasks but MPI sees %d rank(s) (srun needs --mpi=pmix; or use "
                 "Open MPI's mpirun)\n",
                 launched_size, size_);
    finalize();
    std::exit(2);
  }
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
  if (mine.size() > static_cast<size_t>(INT_MAX)) {
    std::fprintf(stderr, "study: rank %d's results exceed 2 GB\n", rank_);
    abort(1);  // this rank alone knows: end every rank
  }
  const int len = static_cast<int>(mine.size());
  std::vector<int> lens(size_), offsets(size_);
  MPI_Allgather(&len, 1, MPI_INT, lens.data(), 1, MPI_INT, MPI_COMM_WORLD);
  long long total = 0;
  for (int r = 0; r < size_; ++r) {
    offsets[r] = static_cast<int>(total);
    total += lens[r];
    if (total > INT_MAX) throw std::runtime_error("study: gathered results exceed 2 GB");  // every rank alike
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

void Cluster::quiet_barrier() const {
  if (!mpi_) return;
#ifdef NHI_HAVE_MPI
  MPI_Request req;
  MPI_Ibarrier(MPI_COMM_WORLD, &req);
  for (int done = 0;;) {
    MPI_Test(&req, &done, MPI_STATUS_IGNORE);
    if (done) return;
    const timespec pause{0, 1000000};  // 1 ms
    nanosleep(&pause, nullptr);
  }
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

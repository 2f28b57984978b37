// The processes of one study run.  Started by `mpirun -np N` or Slurm's `srun`
// (Open MPI), a study runs as N ranks; started plainly, it is one rank and MPI
// is never initialised.  This header and cluster.cpp are the only code that
// knows about MPI: study.hpp's map_cells() distributes a study's cells over the
// ranks and gathers their results onto every rank, so the mathematics, the
// aggregation and the JSON of each study are one code path for any N.
#pragma once

#include <string>
#include <vector>

namespace study {

class Cluster {
 public:
  // The one instance; the first call initialises MPI when the process was
  // started by an MPI launcher (OMPI_COMM_WORLD_SIZE, PMIX_RANK or PMI_RANK in
  // the environment, or srun with several tasks).  A build without MPI started
  // as several ranks, or ranks that MPI does not see as one job, exit 2.
  static Cluster& get();

  int rank() const { return rank_; }
  int size() const { return size_; }
  bool root() const { return rank_ == 0; }
  bool parallel() const { return size_ > 1; }
  // The lowest rank of each node (shared-memory domain), in rank order: the
  // ranks that run timed cells, so that no two timed ranks share cores.
  const std::vector<int>& node_leaders() const { return leaders_; }

  // Every rank's bytes, indexed by rank, on every rank (collective).
  std::vector<std::string> all_gather(const std::string& mine) const;
  // Wait for every rank, sleeping between polls (collective): ranks that have
  // finished their share do not spin on a core another rank is timing on.
  void quiet_barrier() const;

  // End MPI, on every rank together (collective), before the process exits.
  void finalize();
  // Exit with `code` when every rank exits with it (collective).
  [[noreturn]] void exit_all(int code);
  // Exit with `code` from this rank alone: aborts every rank under MPI.
  [[noreturn]] static void abort(int code);

  Cluster(const Cluster&) = delete;
  Cluster& operator=(const Cluster&) = delete;

 private:
  Cluster();
  int rank_ = 0, size_ = 1;
  bool mpi_ = false, finalized_ = false;
  std::vector<int> leaders_{0};
};

// The number of tasks an MPI launcher or srun says it started (1 without one).
int launcher_ranks();

}  // namespace study

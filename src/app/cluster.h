// The processes of one `keithray render`: the ranks of an MPI job when a launcher (mpirun,
// srun) started this process, else this process alone. Only cluster_mpi.cpp includes mpi.h;
// a build without MPI has cluster_single.cpp, a cluster of one.
//
// How a render is shared (docs/scaling.md): rank r renders the pixel rows y with
// y mod N == r, every pixel's samples in the single-process order, so each pixel's sums are
// those of one process bit for bit. After a pass whose next step reads the image's statistics
// (adaptive allocation, the noise rule), every rank receives every other rank's rows of the
// three sums those read; each rank then plans the next pass itself, identically. Rank 0
// gathers the whole state for the outputs and checkpoints.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "render/progressive.h"

namespace kr {

// Per rank, what a render cost it, for the summary.
struct RankCost {
    double busy_seconds = 0;     // CPU time spent in render_pass (the rank's share of the work)
    double combine_seconds = 0;  // wall time spent exchanging rows (and waiting for the others)
    double between_seconds = 0;  // wall time between passes: every rank plans the whole image
    int exchanges = 0;           // passes after which the statistics were exchanged
    uint64_t rays = 0;
};

class Cluster {
public:
    // Joins the MPI job where the environment names a launcher's rank, else a cluster of one
    // without touching MPI. Throws std::runtime_error (one line) where MPI cannot start.
    Cluster(int& argc, char**& argv);
    ~Cluster();  // leaves the MPI job
    Cluster(const Cluster&) = delete;
    Cluster& operator=(const Cluster&) = delete;

    bool distributed() const { return size_ > 1 || mpi_; }
    bool leader() const { return rank_ == 0; }
    int rank() const { return rank_; }
    int size() const { return size_; }

    // Ends every rank of the job with `status` (MPI_Abort), for a failure in one rank that
    // the others would wait on.
    [[noreturn]] void abort(int status) const;
    // Rank 0's `bytes` in every rank.
    void broadcast(std::string& bytes) const;
    // Rank 0's `value` in every rank.
    bool broadcast(bool value) const;
    // The bitwise or of every rank's `flags`, in every rank.
    int any_flags(int flags) const;
    // At rank 0, every rank's `cost` (rank order); elsewhere empty.
    std::vector<RankCost> gather(const RankCost& cost) const;
    // Makes rank 0's `state` whole (every pixel's sums and counts from the rank that drew
    // them) and returns the job's rays and dropped samples there; the other ranks' states are
    // unchanged.
    void gather_state(RenderState& state, uint64_t& rays, uint64_t& nonfinite) const;

    // The driver's hooks that deal rows to the ranks (nullptr for a cluster of one). When
    // `always_combine`, the statistics are exchanged after every pass (the progress line of
    // an open-ended render shows the estimated error).
    std::unique_ptr<PassHooks> deal_rows(bool always_combine) const;
    // What the hooks measured in this rank so far.
    static RankCost cost(const PassHooks& hooks);

private:
    int rank_ = 0, size_ = 1;
    bool mpi_ = false;
};

}  // namespace kr

// The processes of one `keithray render` or `keithray view` (app/view_ranks.h): the ranks of an MPI job when a launcher (mpirun,
// srun) started this process, else this process alone. Only cluster_mpi.cpp includes mpi.h;
// it is the module keithray_mpi.so (core/module.h), loaded with Open MPI only when a
// launcher started this process: a plain run never loads MPI. cluster.cpp is the cluster of
// one, and the program's side of the module.
//
// How a render is shared (docs/scaling.md): rank r renders the pixel rows y with
// y mod N == r, every pixel's samples in the single-process order, so each pixel's sums are
// those of one process bit for bit. Each rank plans its own rows (render/row_share.h,
// RowShare): after a pass whose next step reads the statistics (adaptive allocation, the
// noise rule), it receives the three sums of its rows' neighbouring rows (the 3x3 guard's)
// from the ranks r - 1 and r + 1, and the image-wide sums are gathered as per-row sums that
// every rank adds in row order. Rank 0 holds the whole state, gathered for the outputs and
// checkpoints; every other rank holds only its rows and their neighbours (held_rows).
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "render/progressive.h"

namespace kr {

// Per rank, what a render cost it, for the summary.
struct RankCost {
    double busy_seconds = 0;     // CPU time spent in render_pass (the rank's share of the work)
    double combine_seconds = 0;  // wall time in the exchanges and the --time agreement (waiting included)
    double between_seconds = 0;  // wall time between passes less its exchanges: planning, the noise rule
    int exchanges = 0;           // passes after which the guard rows' statistics were exchanged
    uint64_t rays = 0;
    double received_bytes = 0;   // received in the exchanges between passes
};

// What the MPI module does for Cluster, in a process a launcher started (the same calls as
// Cluster's below, across the job's ranks).
class ClusterBackend {
public:
    virtual ~ClusterBackend() = default;
    virtual int rank() const = 0;
    virtual int size() const = 0;
    virtual std::string failure() const = 0;
    [[noreturn]] virtual void abort(int status) const = 0;
    virtual void broadcast(std::string& bytes) const = 0;
    virtual bool broadcast(bool value) const = 0;
    virtual void broadcast_waiting(std::string& bytes) const = 0;
    virtual int any_flags(int flags) const = 0;
    virtual std::vector<RankCost> gather(const RankCost& cost) const = 0;
    virtual std::vector<int> held_rows(int height) const = 0;
    virtual void scatter_state(RenderState& state) const = 0;
    virtual void gather_state(RenderState& state, uint64_t& rays, uint64_t& nonfinite) const = 0;
    virtual std::unique_ptr<PassHooks> deal_rows() const = 0;
    virtual RankCost cost(const PassHooks& hooks) const = 0;
};
// The module's table (core/module.h): `join` starts MPI (MPI_Init_thread) and returns this
// process's rank; it throws std::runtime_error (one line) where MPI cannot start.
struct MpiModule {
    std::unique_ptr<ClusterBackend> (*join)(int& argc, char**& argv, bool other_thread);
};

class Cluster {
public:
    // Joins the MPI job where the environment names a launcher's rank, else a cluster of one
    // without touching MPI. Throws std::runtime_error (one line) where MPI cannot start.
    // `other_thread`: MPI is called from another thread than this one (the viewer's render
    // thread), one thread at a time (MPI_THREAD_SERIALIZED).
    Cluster(int& argc, char**& argv, bool other_thread = false);
    ~Cluster();  // leaves the MPI job
    Cluster(const Cluster&) = delete;
    Cluster& operator=(const Cluster&) = delete;

    bool distributed() const { return size_ > 1 || mpi_; }
    bool leader() const { return rank_ == 0; }
    int rank() const { return rank_; }
    int size() const { return size_; }

    // With `other_thread`, a failed MPI call (a rank that died) parks the calling thread of
    // rank 0 for ever, and this says why from then on ("" before); another rank exits 1.
    static std::string failure();
    // Ends every rank of the job with `status` (MPI_Abort), for a failure in one rank that
    // the others would wait on.
    [[noreturn]] void abort(int status) const;
    // Rank 0's `bytes` in every rank.
    void broadcast(std::string& bytes) const;
    // Rank 0's `value` in every rank.
    bool broadcast(bool value) const;
    // As broadcast(bytes), for ranks that may wait long for it (the viewer's next command):
    // they poll, sleeping a millisecond between polls, instead of spinning on a core.
    void broadcast_waiting(std::string& bytes) const;
    // The bitwise or of every rank's `flags`, in every rank.
    int any_flags(int flags) const;
    // At rank 0, every rank's `cost` (rank order); elsewhere empty.
    std::vector<RankCost> gather(const RankCost& cost) const;
    // The rows this rank's RenderState holds (RenderState::reset): its own and their
    // neighbours; every row (empty) at rank 0, which gathers the whole state, and alone.
    std::vector<int> held_rows(int height) const;
    // After rank 0 decoded a checkpoint into `state` (every row): every other rank's state
    // (reset to its held_rows) gets its rows of it, with the passes; the rays and dropped
    // samples stay counted at rank 0.
    void scatter_state(RenderState& state) const;
    // Makes rank 0's `state` whole (every pixel's sums and counts, and the two halves of the
    // samples where the states track them, from the rank that drew them) and returns the job's rays and dropped samples there; the other ranks' states are
    // unchanged.
    void gather_state(RenderState& state, uint64_t& rays, uint64_t& nonfinite) const;

    // The driver's hooks that deal rows to the ranks (nullptr for a cluster of one).
    std::unique_ptr<PassHooks> deal_rows() const;
    // What the hooks measured in this rank so far.
    static RankCost cost(const PassHooks& hooks);

private:
    int rank_ = 0, size_ = 1;
    bool mpi_ = false;
    std::unique_ptr<ClusterBackend> backend_;  // the MPI module's, under a launcher
};

}  // namespace kr

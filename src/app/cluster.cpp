// Cluster: this process alone, or under a launcher (mpirun, srun) the ranks of its MPI job
// through the module keithray_mpi.so (cluster_mpi.cpp), loaded only then.
#include <atomic>
#include <cstdlib>
#include <stdexcept>

#include "app/cluster.h"
#include "core/module.h"

namespace kr {

namespace {

// Whether a launcher started this process: Open MPI's mpirun, PMIx (srun --mpi=pmix) or PMI.
bool launched_by_mpi() {
    for (const char* name : {"OMPI_COMM_WORLD_SIZE", "PMIX_RANK", "PMI_RANK"})
        if (std::getenv(name)) return true;
    return false;
}

// The joined job's side, for the static calls (a process joins at most one job).
std::atomic<const ClusterBackend*> g_backend{nullptr};

}  // namespace

Cluster::Cluster(int& argc, char**& argv, bool other_thread) {
    if (!launched_by_mpi()) return;
    // Under a launcher every rank would render (and write) the whole image alone: refused
    // where MPI cannot be had.
    if (!KEITHRAY_MPI_BUILT)
        throw std::runtime_error("this keithray was built without MPI (libopenmpi-dev missing at build time); "
                                 "run it without mpirun, or rebuild after scripts/setup.sh");
    const auto& module = *static_cast<const MpiModule*>(load_module("mpi", nullptr, "MPI", "libopenmpi3"));
    backend_ = module.join(argc, argv, other_thread);
    mpi_ = true;
    rank_ = backend_->rank();
    size_ = backend_->size();
    g_backend.store(backend_.get());
}

Cluster::~Cluster() {
    if (backend_) g_backend.store(nullptr);
}

std::string Cluster::failure() {
    const ClusterBackend* backend = g_backend.load();
    return backend ? backend->failure() : std::string();
}

void Cluster::abort(int status) const {
    if (backend_) backend_->abort(status);
    std::_Exit(status);
}

void Cluster::broadcast(std::string& bytes) const {
    if (backend_) backend_->broadcast(bytes);
}

void Cluster::broadcast_waiting(std::string& bytes) const {
    if (backend_) backend_->broadcast_waiting(bytes);
}

bool Cluster::broadcast(bool value) const { return backend_ ? backend_->broadcast(value) : value; }

int Cluster::any_flags(int flags) const { return backend_ ? backend_->any_flags(flags) : flags; }

std::vector<RankCost> Cluster::gather(const RankCost& cost) const {
    return backend_ ? backend_->gather(cost) : std::vector<RankCost>{cost};
}

void Cluster::gather_state(RenderState& state, uint64_t& rays, uint64_t& nonfinite) const {
    rays = state.rays;
    nonfinite = state.nonfinite_samples;
    if (backend_) backend_->gather_state(state, rays, nonfinite);
}

std::vector<int> Cluster::held_rows(int height) const { return backend_ ? backend_->held_rows(height) : std::vector<int>{}; }

void Cluster::scatter_state(RenderState& state) const {
    if (backend_) backend_->scatter_state(state);
}

std::unique_ptr<PassHooks> Cluster::deal_rows() const { return backend_ ? backend_->deal_rows() : nullptr; }

RankCost Cluster::cost(const PassHooks& hooks) {
    const ClusterBackend* backend = g_backend.load();
    return backend ? backend->cost(hooks) : RankCost{};
}

}  // namespace kr

// Cluster for a build without MPI: this process alone. Under a launcher it refuses to start,
// since every rank would render (and write) the whole image.
#include <cstdlib>
#include <stdexcept>

#include "app/cluster.h"

namespace kr {

Cluster::Cluster(int&, char**&, bool) {
    for (const char* name : {"OMPI_COMM_WORLD_SIZE", "PMIX_RANK", "PMI_RANK"})
        if (std::getenv(name))
            throw std::runtime_error("this keithray was built without MPI (libopenmpi-dev missing at build time); "
                                     "run it without mpirun, or rebuild after scripts/setup.sh");
}
Cluster::~Cluster() = default;
std::string Cluster::failure() { return {}; }
void Cluster::abort(int status) const { std::_Exit(status); }
void Cluster::broadcast(std::string&) const {}
void Cluster::broadcast_waiting(std::string&) const {}
bool Cluster::broadcast(bool value) const { return value; }
int Cluster::any_flags(int flags) const { return flags; }
std::vector<RankCost> Cluster::gather(const RankCost& cost) const { return {cost}; }
void Cluster::gather_state(RenderState& state, uint64_t& rays, uint64_t& nonfinite) const {
    rays = state.rays;
    nonfinite = state.nonfinite_samples;
}
std::vector<int> Cluster::held_rows(int) const { return {}; }
void Cluster::scatter_state(RenderState&) const {}
std::unique_ptr<PassHooks> Cluster::deal_rows() const { return nullptr; }
RankCost Cluster::cost(const PassHooks&) { return {}; }

}  // namespace kr

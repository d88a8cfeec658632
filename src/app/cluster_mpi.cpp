// Cluster over MPI (Open MPI): the only file that includes mpi.h.
#include <mpi.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <chrono>
#include <cstdint>
#include <stdexcept>

#include "app/cluster.h"

namespace kr {

namespace {

// Whether a launcher started this process: Open MPI's mpirun, PMIx (srun --mpi=pmix) or PMI.
bool launched_by_mpi() {
    for (const char* name : {"OMPI_COMM_WORLD_SIZE", "PMIX_RANK", "PMI_RANK"})
        if (std::getenv(name)) return true;
    return false;
}

double cpu_seconds() {
    timespec t{};
    ::clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
    return double(t.tv_sec) + 1e-9 * double(t.tv_nsec);
}

double wall_seconds() {
    return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

// Counts of T as MPI counts: in bytes (MPI_BYTE, which MPI copies fastest) while the whole
// image's bytes fit an int, else in elements of a contiguous type (from about 8K images).
template <class T>
class Counted {
public:
    explicit Counted(size_t total) : scale_(total * sizeof(T) <= size_t(INT32_MAX) ? int(sizeof(T)) : 1) {
        if (scale_ == 1) {
            MPI_Type_contiguous(int(sizeof(T)), MPI_BYTE, &type_);
            MPI_Type_commit(&type_);
        }
    }
    ~Counted() {
        if (scale_ == 1) MPI_Type_free(&type_);
    }
    MPI_Datatype type() const { return type_; }
    int count(size_t elements) const { return int(elements) * scale_; }
    std::vector<int> counts(const std::vector<int>& elements) const {
        std::vector<int> c(elements);
        for (int& v : c) v *= scale_;
        return c;
    }

private:
    int scale_;
    MPI_Datatype type_ = MPI_BYTE;
};

// Rows dealt round-robin: rank r holds rows r, r+N, r+2N, ...; packed in that order.
struct RowDeal {
    int rank, size, width, height;
    int rows_of(int r) const { return r < height ? (height - r + size - 1) / size : 0; }
    std::vector<int> counts() const {  // pixels per rank
        std::vector<int> c(static_cast<size_t>(size));
        for (int r = 0; r < size; ++r) c[size_t(r)] = rows_of(r) * width;
        return c;
    }
    std::vector<int> offsets(const std::vector<int>& counts) const {
        std::vector<int> o(counts.size(), 0);
        for (size_t r = 1; r < counts.size(); ++r) o[r] = o[r - 1] + counts[r - 1];
        return o;
    }
    // This rank's rows of `field`, packed in order into `out`.
    template <class T>
    void pack(const std::vector<T>& field, std::vector<char>& out) const {
        const size_t row = size_t(width) * sizeof(T);
        const int rows = rows_of(rank);
        out.resize(size_t(rows) * row);
#pragma omp parallel for schedule(static)
        for (int k = 0; k < rows; ++k)
            std::memcpy(out.data() + size_t(k) * row, field.data() + size_t(rank + k * size) * size_t(width), row);
    }
    template <class T>
    void unpack(const std::vector<char>& all, const std::vector<int>& offsets, std::vector<T>& field) const {
        const size_t row = size_t(width) * sizeof(T);
        // Row y is rank (y mod N)'s row y div N.
#pragma omp parallel for schedule(static)
        for (int y = 0; y < height; ++y)
            std::memcpy(field.data() + size_t(y) * size_t(width),
                        all.data() + size_t(offsets[size_t(y % size)]) * sizeof(T) + size_t(y / size) * row, row);
    }
    // Every rank's rows of `field` in every rank (all) or in rank 0 only. `mine` and
    // `gathered` are buffers kept between calls: fresh pages cost more than the copy.
    template <class T>
    void exchange(std::vector<T>& field, bool all, std::vector<char>& mine, std::vector<char>& gathered) const {
        const Counted<T> as(field.size());
        const std::vector<int> counts = this->counts(), offsets = this->offsets(counts);
        const std::vector<int> mpi_counts = as.counts(counts), mpi_offsets = as.counts(offsets);
        if (all || rank == 0) gathered.resize(field.size() * sizeof(T));
        pack(field, mine);
        if (all)
            MPI_Allgatherv(mine.data(), as.count(mine.size() / sizeof(T)), as.type(), gathered.data(),
                           mpi_counts.data(), mpi_offsets.data(), as.type(), MPI_COMM_WORLD);
        else
            MPI_Gatherv(mine.data(), as.count(mine.size() / sizeof(T)), as.type(), gathered.data(), mpi_counts.data(),
                        mpi_offsets.data(), as.type(), 0, MPI_COMM_WORLD);
        if (all || rank == 0) unpack(gathered, offsets, field);
    }
};

// The driver's hooks of one rank: its rows masked in around each pass, the statistics of its
// rows' neighbours (the 3x3 guard's) received from the ranks that own them when the plan or
// the noise rule reads them, and the per-row sums combined (RowShare).
class DealtRows final : public PassHooks, public RowShare {
public:
    DealtRows(int rank, int size) : RowShare(rank, size) {}

    void before_pass(RenderState& state) override {
        // render_pass samples only this rank's rows (of the noise rule's mask, if any).
        if (owned_rows_.size() != size_t(state.height)) {
            owned_rows_.assign(size_t(state.height), 0);
            for (int y : rows_owned(this, state.height)) owned_rows_[size_t(y)] = 1;
        }
        state.buffers().active_rows = owned_rows_;
        // Planning and the noise rule since the last pass, less their exchanges.
        if (passes_ > 0) cost_.between_seconds += wall_seconds() - pass_end_ - (cost_.combine_seconds - combine_mark_);
        cpu_start_ = cpu_seconds();
    }

    void after_pass(RenderState& state, bool statistics) override {
        cost_.busy_seconds += cpu_seconds() - cpu_start_;
        state.buffers().active_rows.clear();
        ++passes_;
        pass_end_ = wall_seconds();
        combine_mark_ = cost_.combine_seconds;
        if (statistics) {
            receive_guard_rows(state);
            ++cost_.exchanges;
        }
    }

    bool any(bool stop) override {
        const double start = wall_seconds();  // mostly waiting for the slowest rank's pass
        int flag = stop, result = 0;
        MPI_Allreduce(&flag, &result, 1, MPI_INT, MPI_LOR, MPI_COMM_WORLD);
        cost_.combine_seconds += wall_seconds() - start;
        return result != 0;
    }

    const RowShare* rows() const override { return this; }

    // Every rank's rows of `values` (`fields` doubles a row), gathered and put in row order.
    void combine(std::vector<double>& values, int fields) const override {
        const double start = wall_seconds();
        const int height = int(values.size() / size_t(fields));
        const RowDeal deal{index(), count(), fields, height};
        std::vector<double> mine;
        for (int y : rows_owned(this, height))
            mine.insert(mine.end(), values.begin() + ptrdiff_t(y) * fields, values.begin() + ptrdiff_t(y + 1) * fields);
        const std::vector<int> counts = deal.counts(), offsets = deal.offsets(counts);
        std::vector<double> all(values.size());
        MPI_Allgatherv(mine.data(), int(mine.size()), MPI_DOUBLE, all.data(), counts.data(), offsets.data(),
                       MPI_DOUBLE, MPI_COMM_WORLD);
        // Row y is rank (y mod N)'s row y div N.
        for (int y = 0; y < height; ++y)
            std::copy_n(all.begin() + offsets[size_t(y % count())] + ptrdiff_t(y / count()) * fields, fields,
                        values.begin() + ptrdiff_t(y) * fields);
        cost_.received_bytes += double((values.size() - mine.size()) * sizeof(double));
        cost_.combine_seconds += wall_seconds() - start;
    }

    mutable RankCost cost_;

private:
    // The rows the 3x3 guard reads besides this rank's own: rows y - 1 and y + 1 of each own
    // row y, which ranks r - 1 and r + 1 (mod N) own. Each rank sends its rows' three sums to
    // both and receives theirs (from the one other rank when N = 2).
    void receive_guard_rows(RenderState& state) {
        if (count() == 1) return;
        const double start = wall_seconds();
        const int width = state.width, height = state.height;
        const RowDeal deal{index(), count(), width, height};
        PixelBuffers& px = state.buffers();
        const size_t w = size_t(width);
        const size_t row_bytes = w * (sizeof(Color) + sizeof(double) + sizeof(uint32_t));
        const std::vector<int> own = rows_owned(this, height);
        send_.resize(own.size() * row_bytes);
#pragma omp parallel for schedule(static)
        for (size_t k = 0; k < own.size(); ++k) {
            char* at = send_.data() + k * row_bytes;
            const size_t first = size_t(own[k]) * w;
            at = std::copy_n(reinterpret_cast<const char*>(&px.radiance_sum[first]), w * sizeof(Color), at);
            at = std::copy_n(reinterpret_cast<const char*>(&px.luminance_sq_sum[first]), w * sizeof(double), at);
            std::copy_n(reinterpret_cast<const char*>(&px.sample_count[first]), w * sizeof(uint32_t), at);
        }
        MPI_Datatype row;
        MPI_Type_contiguous(int(row_bytes), MPI_BYTE, &row);
        MPI_Type_commit(&row);
        const int before = (index() + count() - 1) % count(), after = (index() + 1) % count();
        std::vector<int> neighbours = {before};
        if (after != before) neighbours.push_back(after);
        received_.resize(neighbours.size());
        std::vector<MPI_Request> requests;
        for (size_t n = 0; n < neighbours.size(); ++n) {
            received_[n].resize(size_t(deal.rows_of(neighbours[n])) * row_bytes);
            requests.emplace_back();
            MPI_Irecv(received_[n].data(), deal.rows_of(neighbours[n]), row, neighbours[n], 0, MPI_COMM_WORLD,
                      &requests.back());
        }
        for (int to : neighbours) {
            requests.emplace_back();
            MPI_Isend(send_.data(), int(own.size()), row, to, 0, MPI_COMM_WORLD, &requests.back());
        }
        MPI_Waitall(int(requests.size()), requests.data(), MPI_STATUSES_IGNORE);
        MPI_Type_free(&row);
        for (size_t n = 0; n < neighbours.size(); ++n) {
            const int rows = deal.rows_of(neighbours[n]);
#pragma omp parallel for schedule(static)
            for (int k = 0; k < rows; ++k) {
                const char* at = received_[n].data() + size_t(k) * row_bytes;
                const size_t first = size_t(neighbours[n] + k * count()) * w;
                std::copy_n(at, w * sizeof(Color), reinterpret_cast<char*>(&px.radiance_sum[first]));
                at += w * sizeof(Color);
                std::copy_n(at, w * sizeof(double), reinterpret_cast<char*>(&px.luminance_sq_sum[first]));
                at += w * sizeof(double);
                std::copy_n(at, w * sizeof(uint32_t), reinterpret_cast<char*>(&px.sample_count[first]));
            }
            cost_.received_bytes += double(received_[n].size());
        }
        cost_.combine_seconds += wall_seconds() - start;
    }

    std::vector<uint8_t> owned_rows_;  // 1 for this rank's rows
    std::vector<char> send_;      // the guard rows' buffers, kept between passes
    std::vector<std::vector<char>> received_;
    double cpu_start_ = 0, pass_end_ = 0, combine_mark_ = 0;
    int passes_ = 0;
};

}  // namespace

Cluster::Cluster(int& argc, char**& argv) {
    if (!launched_by_mpi()) return;
    // Only the main thread calls MPI; OpenMP's threads render between the calls.
    int provided = 0;
    if (MPI_Init_thread(&argc, &argv, MPI_THREAD_FUNNELED, &provided) != MPI_SUCCESS)
        throw std::runtime_error("MPI could not start (MPI_Init_thread failed)");
    mpi_ = true;
    MPI_Comm_rank(MPI_COMM_WORLD, &rank_);
    MPI_Comm_size(MPI_COMM_WORLD, &size_);
}

Cluster::~Cluster() {
    if (mpi_) MPI_Finalize();
}

void Cluster::abort(int status) const {
    std::fflush(stdout);
    std::fflush(stderr);
    MPI_Abort(MPI_COMM_WORLD, status);
    std::_Exit(status);
}

void Cluster::broadcast(std::string& bytes) const {
    if (!mpi_) return;
    unsigned long long size = bytes.size();
    MPI_Bcast(&size, 1, MPI_UNSIGNED_LONG_LONG, 0, MPI_COMM_WORLD);
    bytes.resize(size_t(size));
    // In pieces of at most 1 GiB: MPI counts are ints.
    constexpr size_t kPiece = size_t(1) << 30;
    for (size_t at = 0; at < bytes.size(); at += kPiece)
        MPI_Bcast(bytes.data() + at, int(std::min(kPiece, bytes.size() - at)), MPI_BYTE, 0, MPI_COMM_WORLD);
}

bool Cluster::broadcast(bool value) const {
    if (!mpi_) return value;
    int v = value;
    MPI_Bcast(&v, 1, MPI_INT, 0, MPI_COMM_WORLD);
    return v != 0;
}

int Cluster::any_flags(int flags) const {
    if (!mpi_) return flags;
    int result = 0;
    MPI_Allreduce(&flags, &result, 1, MPI_INT, MPI_BOR, MPI_COMM_WORLD);
    return result;
}

std::vector<RankCost> Cluster::gather(const RankCost& cost) const {
    if (!mpi_) return {cost};
    constexpr int kFields = 6;
    const double mine[kFields] = {cost.busy_seconds,       cost.combine_seconds, cost.between_seconds,
                                  double(cost.exchanges), double(cost.rays),    cost.received_bytes};
    std::vector<double> all(leader() ? kFields * size_t(size_) : 0);
    MPI_Gather(mine, kFields, MPI_DOUBLE, all.data(), kFields, MPI_DOUBLE, 0, MPI_COMM_WORLD);
    std::vector<RankCost> costs;
    for (size_t r = 0; r < all.size(); r += kFields)
        costs.push_back({all[r], all[r + 1], all[r + 2], int(all[r + 3]), uint64_t(all[r + 4]), all[r + 5]});
    return costs;
}

void Cluster::gather_state(RenderState& state, uint64_t& rays, uint64_t& nonfinite) const {
    rays = state.rays;
    nonfinite = state.nonfinite_samples;
    if (!mpi_) return;
    const RowDeal deal{rank_, size_, state.width, state.height};
    std::vector<char> mine, gathered;
    deal.exchange(state.buffers().radiance_sum, false, mine, gathered);
    deal.exchange(state.buffers().radiance_compensation, false, mine, gathered);
    deal.exchange(state.buffers().depth_sum, false, mine, gathered);
    deal.exchange(state.buffers().luminance_sq_sum, false, mine, gathered);
    deal.exchange(state.buffers().radiance_sq_sum, false, mine, gathered);
    deal.exchange(state.buffers().sample_count, false, mine, gathered);
    deal.exchange(state.buffers().sample_index, false, mine, gathered);
    // The noise rule's mask and the plan's credit are set by each rank on its own rows only.
    if (!state.buffers().active.empty()) deal.exchange(state.buffers().active, false, mine, gathered);
    if (!state.buffers().sample_credit.empty()) deal.exchange(state.buffers().sample_credit, false, mine, gathered);
    const unsigned long long counts[2] = {state.rays, state.nonfinite_samples};
    unsigned long long sum[2] = {0, 0};
    MPI_Reduce(counts, sum, 2, MPI_UNSIGNED_LONG_LONG, MPI_SUM, 0, MPI_COMM_WORLD);
    rays = sum[0];
    nonfinite = sum[1];
}

std::unique_ptr<PassHooks> Cluster::deal_rows() const {
    if (!mpi_) return nullptr;
    return std::make_unique<DealtRows>(rank_, size_);
}

RankCost Cluster::cost(const PassHooks& hooks) {
    const auto* dealt = dynamic_cast<const DealtRows*>(&hooks);
    return dealt ? dealt->cost_ : RankCost{};
}

}  // namespace kr

// Cluster over MPI (Open MPI): the only file that includes mpi.h. Built as the module
// keithray_mpi.so (core/module.h), which cluster.cpp loads, with Open MPI, only in a process
// that a launcher started.
#include <mpi.h>

#include <algorithm>
#include <atomic>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <chrono>
#include <cstdint>
#include <stdexcept>
#include <thread>

#include "app/cluster.h"

namespace kr {

namespace {

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

// The rows as row_owners deals them: each rank's packed in order, ranks in order.
struct RowDeal {
    int rank, size, width, height;
    std::vector<int> owner;  // per row, its rank
    std::vector<int> place;  // per row, its place among its rank's rows
    std::vector<int> rows;   // per rank, its rows

    RowDeal(int rank_, int size_, int width_, int height_)
        : rank(rank_), size(size_), width(width_), height(height_), owner(row_owners(size_, height_)),
          place(owner.size()), rows(size_t(size_), 0) {
        for (size_t y = 0; y < owner.size(); ++y) place[y] = rows[size_t(owner[y])]++;
    }
    int rows_of(int r) const { return rows[size_t(r)]; }
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
    // This rank's rows of `field` (of `state`'s buffers), packed in order into `out`.
    template <class T>
    void pack(const RenderState& state, const std::vector<T>& field, std::vector<char>& out) const {
        const size_t row = size_t(width) * sizeof(T);
        out.resize(size_t(rows_of(rank)) * row);
#pragma omp parallel for schedule(static)
        for (int y = 0; y < height; ++y)
            if (owner[size_t(y)] == rank)
                std::memcpy(out.data() + size_t(place[size_t(y)]) * row, field.data() + state.row_start(y), row);
    }
    template <class T>
    void unpack(const std::vector<char>& all, const std::vector<int>& offsets, std::vector<T>& field) const {
        const size_t row = size_t(width) * sizeof(T);
#pragma omp parallel for schedule(static)
        for (int y = 0; y < height; ++y)
            std::memcpy(field.data() + size_t(y) * size_t(width),
                        all.data() + size_t(offsets[size_t(owner[size_t(y)])]) * sizeof(T) + size_t(place[size_t(y)]) * row,
                        row);
    }
    // Every rank's rows of `field` in rank 0, whose state holds every row. `mine` and
    // `gathered` are buffers kept between calls: fresh pages cost more than the copy.
    template <class T>
    void gather(const RenderState& state, std::vector<T>& field, std::vector<char>& mine,
                std::vector<char>& gathered) const {
        const Counted<T> as(size_t(width) * size_t(height));  // the same in every rank
        const std::vector<int> counts = this->counts(), offsets = this->offsets(counts);
        const std::vector<int> mpi_counts = as.counts(counts), mpi_offsets = as.counts(offsets);
        if (rank == 0) gathered.resize(field.size() * sizeof(T));
        pack(state, field, mine);
        MPI_Gatherv(mine.data(), as.count(mine.size() / sizeof(T)), as.type(), gathered.data(), mpi_counts.data(),
                    mpi_offsets.data(), as.type(), 0, MPI_COMM_WORLD);
        if (rank == 0) unpack(gathered, offsets, field);
    }
    // Rank 0's `field` (every row) to every other rank, each receiving the rows its state
    // holds (rows_guarded), in order: its buffers' layout.
    template <class T>
    void scatter(std::vector<T>& field) const {
        const Counted<T> as(3 * size_t(width) * size_t(height));  // a rank's rows and their neighbours
        std::vector<int> counts(static_cast<size_t>(size)), offsets(static_cast<size_t>(size), 0);
        for (int r = 0; r < size; ++r) {
            counts[size_t(r)] = r == 0 ? 0 : int(rows_guarded(r, size, height).size()) * width;
            if (r > 0) offsets[size_t(r)] = offsets[size_t(r - 1)] + counts[size_t(r - 1)];
        }
        std::vector<T> sent;
        if (rank == 0) {
            sent.reserve(size_t(offsets.back()) + size_t(counts.back()));
            for (int r = 1; r < size; ++r)
                for (int y : rows_guarded(r, size, height))
                    sent.insert(sent.end(), field.begin() + ptrdiff_t(y) * width, field.begin() + ptrdiff_t(y + 1) * width);
        }
        const std::vector<int> mpi_counts = as.counts(counts), mpi_offsets = as.counts(offsets);
        // A rank receives what is sent to it: none for one without rows (an image with fewer
        // rows than ranks), whose state holds every row, or it waits for ever.
        MPI_Scatterv(sent.data(), mpi_counts.data(), mpi_offsets.data(), as.type(), rank == 0 ? MPI_IN_PLACE : field.data(),
                     as.count(rank == 0 ? 0 : size_t(counts[size_t(rank)])), as.type(), 0, MPI_COMM_WORLD);
    }
};

class DealtRows final : public PassHooks, public RowShare {
public:
    DealtRows(int rank, int size) : RowShare(rank, size) {}

    void before_pass(RenderState& state) override {
        // render_pass samples only this rank's rows (of the noise rule's mask, if any).
        if (owned_rows_.size() != size_t(state.height)) {
            owned_rows_.assign(size_t(state.height), 0);
            for (int y : rows_owned(this, state.height)) owned_rows_[size_t(y)] = 1;
        }
        state.active_rows = owned_rows_;
        // Planning and the noise rule since the last pass, less their exchanges.
        if (passes_ > 0) cost_.between_seconds += wall_seconds() - pass_end_ - (cost_.combine_seconds - combine_mark_);
        cpu_start_ = cpu_seconds();
    }

    void after_pass(RenderState& state, bool statistics) override {
        cost_.busy_seconds += cpu_seconds() - cpu_start_;
        state.active_rows.clear();
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
        for (int y = 0; y < height; ++y)
            std::copy_n(all.begin() + offsets[size_t(deal.owner[size_t(y)])] + ptrdiff_t(deal.place[size_t(y)]) * fields,
                        fields, values.begin() + ptrdiff_t(y) * fields);
        cost_.received_bytes += double((values.size() - mine.size()) * sizeof(double));
        cost_.combine_seconds += wall_seconds() - start;
    }

    mutable RankCost cost_;

private:
    // The rows the 3x3 guard reads besides this rank's own: the rows next to its blocks,
    // which the ranks owning the neighbouring blocks own. Each rank sends every such
    // neighbour its rows next to that neighbour's (their three sums) and receives theirs; both
    // sides list them in row order from row_owners.
    void receive_guard_rows(RenderState& state) {
        if (count() == 1) return;
        const double start = wall_seconds();
        const int width = state.width, height = state.height;
        const RowDeal deal{index(), count(), width, height};
        PixelBuffers& px = state.buffers();
        const size_t w = size_t(width);
        const size_t row_bytes = w * kGuardRowBytesPerPixel;
        // Per other rank, in row order: this rank's rows next to one of its rows (sent), and
        // its rows next to one of this rank's (received). One pass over the rows, where the
        // block boundaries are.
        std::vector<std::vector<int>> out(static_cast<size_t>(count())), in(static_cast<size_t>(count()));
        for (int y = 0; y < height; ++y) {
            const int owner = deal.owner[size_t(y)];
            for (const int next : {y - 1, y + 1}) {
                if (next < 0 || next >= height) continue;
                const int other = deal.owner[size_t(next)];
                if (other == owner) continue;
                std::vector<int>* rows = owner == index() ? &out[size_t(other)] : other == index() ? &in[size_t(owner)] : nullptr;
                if (rows && (rows->empty() || rows->back() != y)) rows->push_back(y);
            }
        }
        std::vector<int> neighbours;
        std::vector<std::vector<int>> sent_rows, received_rows;
        for (int r = 0; r < count(); ++r) {
            if (out[size_t(r)].empty()) continue;  // then neither side is next to the other
            neighbours.push_back(r);
            sent_rows.push_back(std::move(out[size_t(r)]));
            received_rows.push_back(std::move(in[size_t(r)]));
        }
        send_.resize(neighbours.size());
        received_.resize(neighbours.size());
        MPI_Datatype row;
        MPI_Type_contiguous(int(row_bytes), MPI_BYTE, &row);
        MPI_Type_commit(&row);
        std::vector<MPI_Request> requests;
        for (size_t n = 0; n < neighbours.size(); ++n) {
            received_[n].resize(received_rows[n].size() * row_bytes);
            requests.emplace_back();
            MPI_Irecv(received_[n].data(), int(received_rows[n].size()), row, neighbours[n], 0, MPI_COMM_WORLD,
                      &requests.back());
        }
        for (size_t n = 0; n < neighbours.size(); ++n) {
            const std::vector<int>& rows = sent_rows[n];
            send_[n].resize(rows.size() * row_bytes);
#pragma omp parallel for schedule(static)
            for (size_t k = 0; k < rows.size(); ++k) {
                char* at = send_[n].data() + k * row_bytes;
                const size_t first = state.row_start(rows[k]);
                at = std::copy_n(reinterpret_cast<const char*>(&px.radiance_sum[first]), w * sizeof(Color), at);
                at = std::copy_n(reinterpret_cast<const char*>(&px.luminance_sq_sum[first]), w * sizeof(double), at);
                std::copy_n(reinterpret_cast<const char*>(&px.sample_count[first]), w * sizeof(uint32_t), at);
            }
            requests.emplace_back();
            MPI_Isend(send_[n].data(), int(rows.size()), row, neighbours[n], 0, MPI_COMM_WORLD, &requests.back());
        }
        MPI_Waitall(int(requests.size()), requests.data(), MPI_STATUSES_IGNORE);
        MPI_Type_free(&row);
        for (size_t n = 0; n < neighbours.size(); ++n) {
            const std::vector<int>& rows = received_rows[n];
#pragma omp parallel for schedule(static)
            for (size_t k = 0; k < rows.size(); ++k) {
                const char* at = received_[n].data() + k * row_bytes;
                const size_t first = state.row_start(rows[k]);
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
    // The guard rows' buffers, per neighbour, kept between passes.
    std::vector<std::vector<char>> send_, received_;
    double cpu_start_ = 0, pass_end_ = 0, combine_mark_ = 0;
    int passes_ = 0;
};

std::atomic<bool> g_claimed{false}, g_failed{false};  // the first failure is being, has been recorded
char g_failure[MPI_MAX_ERROR_STRING + 64] = "";

void on_mpi_error(MPI_Comm*, int* code, ...) {
    int rank = 0, length = 0;
    MPI_Comm_rank(MPI_COMM_WORLD, &rank);
    char text[MPI_MAX_ERROR_STRING] = "";
    MPI_Error_string(*code, text, &length);
    if (rank != 0) {
        std::fprintf(stderr, "error: rank %d: MPI: %s\n", rank, text);
        std::fflush(stderr);
        std::_Exit(1);
    }
    if (!g_claimed.exchange(true)) {
        std::snprintf(g_failure, sizeof g_failure, "an MPI call failed (%s)", text);
        g_failed.store(true);
    }
    for (;;) std::this_thread::sleep_for(std::chrono::hours(1));
}

// This rank of the job that launched the process (ClusterBackend's calls, cluster.h).
class MpiCluster final : public ClusterBackend {
public:
    MpiCluster(int& argc, char**& argv, bool other_thread);
    ~MpiCluster() override;
    int rank() const override { return rank_; }
    int size() const override { return size_; }
    std::string failure() const override;
    [[noreturn]] void abort(int status) const override;
    void broadcast(std::string& bytes) const override;
    bool broadcast(bool value) const override;
    void broadcast_waiting(std::string& bytes) const override;
    int any_flags(int flags) const override;
    std::vector<RankCost> gather(const RankCost& cost) const override;
    std::vector<int> held_rows(int height) const override;
    void scatter_state(RenderState& state) const override;
    void gather_state(RenderState& state, uint64_t& rays, uint64_t& nonfinite) const override;
    std::unique_ptr<PassHooks> deal_rows() const override;
    RankCost cost(const PassHooks& hooks) const override;

private:
    bool leader() const { return rank_ == 0; }
    int rank_ = 0, size_ = 1;
    bool mpi_ = false;
};

}  // namespace

std::string MpiCluster::failure() const { return g_failed.load() ? std::string(g_failure) : std::string(); }

MpiCluster::MpiCluster(int& argc, char**& argv, bool other_thread) {
    // One thread calls MPI at a time; OpenMP's threads render between the calls.
    const int level = other_thread ? MPI_THREAD_SERIALIZED : MPI_THREAD_FUNNELED;
    int provided = 0;
    if (MPI_Init_thread(&argc, &argv, level, &provided) != MPI_SUCCESS)
        throw std::runtime_error("MPI could not start (MPI_Init_thread failed)");
    if (provided < level) {
        MPI_Finalize();
        throw std::runtime_error("this MPI library does not let another thread call it (no MPI_THREAD_SERIALIZED)");
    }
    if (other_thread) {
        // A failed call (a peer that died) parks rank 0's calling thread and records why,
        // for its window to say; another rank exits. MPI's default would end rank 0 at once.
        MPI_Errhandler handler;
        MPI_Comm_create_errhandler(on_mpi_error, &handler);
        MPI_Comm_set_errhandler(MPI_COMM_WORLD, handler);
        MPI_Errhandler_free(&handler);
    }
    mpi_ = true;
    MPI_Comm_rank(MPI_COMM_WORLD, &rank_);
    MPI_Comm_size(MPI_COMM_WORLD, &size_);
}

MpiCluster::~MpiCluster() {
    if (mpi_) MPI_Finalize();
}

void MpiCluster::abort(int status) const {
    std::fflush(stdout);
    std::fflush(stderr);
    MPI_Abort(MPI_COMM_WORLD, status);
    std::_Exit(status);
}

namespace {

// Rank 0's `bytes`, whose size every rank already has, into every rank's.
void broadcast_bytes(std::string& bytes, unsigned long long size) {
    bytes.resize(size_t(size));
    // In pieces of at most 1 GiB: MPI counts are ints.
    constexpr size_t kPiece = size_t(1) << 30;
    for (size_t at = 0; at < bytes.size(); at += kPiece)
        MPI_Bcast(bytes.data() + at, int(std::min(kPiece, bytes.size() - at)), MPI_BYTE, 0, MPI_COMM_WORLD);
}

}  // namespace

void MpiCluster::broadcast(std::string& bytes) const {
    if (!mpi_) return;
    unsigned long long size = bytes.size();
    MPI_Bcast(&size, 1, MPI_UNSIGNED_LONG_LONG, 0, MPI_COMM_WORLD);
    broadcast_bytes(bytes, size);
}

void MpiCluster::broadcast_waiting(std::string& bytes) const {
    if (!mpi_) return;
    unsigned long long size = bytes.size();
    MPI_Request request;
    MPI_Ibcast(&size, 1, MPI_UNSIGNED_LONG_LONG, 0, MPI_COMM_WORLD, &request);
    if (leader()) MPI_Wait(&request, MPI_STATUS_IGNORE);
    else
        for (int done = 0; MPI_Test(&request, &done, MPI_STATUS_IGNORE), !done;)
            std::this_thread::sleep_for(std::chrono::milliseconds(1));
    broadcast_bytes(bytes, size);
}

bool MpiCluster::broadcast(bool value) const {
    if (!mpi_) return value;
    int v = value;
    MPI_Bcast(&v, 1, MPI_INT, 0, MPI_COMM_WORLD);
    return v != 0;
}

int MpiCluster::any_flags(int flags) const {
    if (!mpi_) return flags;
    int result = 0;
    MPI_Allreduce(&flags, &result, 1, MPI_INT, MPI_BOR, MPI_COMM_WORLD);
    return result;
}

std::vector<RankCost> MpiCluster::gather(const RankCost& cost) const {
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

void MpiCluster::gather_state(RenderState& state, uint64_t& rays, uint64_t& nonfinite) const {
    if (!mpi_) return;
    const RowDeal deal{rank_, size_, state.width, state.height};
    std::vector<char> mine, gathered;
    PixelBuffers& px = state.buffers();
    deal.gather(state, px.radiance_sum, mine, gathered);
    deal.gather(state, px.radiance_compensation, mine, gathered);
    deal.gather(state, px.depth_sum, mine, gathered);
    deal.gather(state, px.luminance_sq_sum, mine, gathered);
    deal.gather(state, px.radiance_sq_sum, mine, gathered);
    deal.gather(state, px.sample_count, mine, gathered);
    deal.gather(state, px.sample_index, mine, gathered);
    // The noise rule's mask and the plan's credit are set by each rank on its own rows only.
    if (!state.plan.active.empty()) deal.gather(state, state.plan.active, mine, gathered);
    if (!state.plan.sample_credit.empty()) deal.gather(state, state.plan.sample_credit, mine, gathered);
    if (state.tracks_halves()) {  // with --denoise and in the viewer: the final denoiser reads them
        deal.gather(state, px.half_sum, mine, gathered);
        deal.gather(state, px.half_count, mine, gathered);
    }
    const unsigned long long counts[2] = {state.rays, state.nonfinite_samples};
    unsigned long long sum[2] = {0, 0};
    MPI_Reduce(counts, sum, 2, MPI_UNSIGNED_LONG_LONG, MPI_SUM, 0, MPI_COMM_WORLD);
    rays = sum[0];
    nonfinite = sum[1];
}

void MpiCluster::scatter_state(RenderState& state) const {
    if (!mpi_) return;
    const RowDeal deal{rank_, size_, state.width, state.height};
    PixelBuffers& px = state.buffers();
    // The counters and which optional buffers are in use, then each buffer.
    long long counters[5] = {state.passes, (long long)state.nonfinite_samples, !state.plan.active.empty(),
                             !state.plan.sample_credit.empty(), state.tracks_halves()};
    MPI_Bcast(counters, 5, MPI_LONG_LONG, 0, MPI_COMM_WORLD);
    if (!leader()) {
        state.passes = int(counters[0]);
        state.nonfinite_samples = 0;  // counted once, at rank 0
        state.rays = 0;
        if (counters[2]) state.plan.active.resize(px.sample_count.size());
        if (counters[3]) state.plan.sample_credit.resize(px.sample_count.size());
        if (counters[4] && !state.tracks_halves()) state.track_halves();
    }
    deal.scatter(px.radiance_sum);
    deal.scatter(px.radiance_compensation);
    deal.scatter(px.depth_sum);
    deal.scatter(px.luminance_sq_sum);
    deal.scatter(px.radiance_sq_sum);
    deal.scatter(px.sample_count);
    deal.scatter(px.sample_index);
    if (counters[2]) deal.scatter(state.plan.active);
    if (counters[3]) deal.scatter(state.plan.sample_credit);
    if (counters[4]) {  // a checkpoint of a render with --denoise: the final denoiser's halves
        deal.scatter(px.half_sum);
        deal.scatter(px.half_count);
    }
}

std::vector<int> MpiCluster::held_rows(int height) const {
    if (!mpi_ || leader()) return {};
    return rows_guarded(rank_, size_, height);
}

std::unique_ptr<PassHooks> MpiCluster::deal_rows() const {
    if (!mpi_) return nullptr;
    return std::make_unique<DealtRows>(rank_, size_);
}

RankCost MpiCluster::cost(const PassHooks& hooks) const {
    const auto* dealt = dynamic_cast<const DealtRows*>(&hooks);
    return dealt ? dealt->cost_ : RankCost{};
}

namespace {

std::unique_ptr<ClusterBackend> join(int& argc, char**& argv, bool other_thread) {
    return std::make_unique<MpiCluster>(argc, argv, other_thread);
}

constexpr MpiModule kModule{join};

}  // namespace

}  // namespace kr

// The module's entry point (core/module.h).
extern "C" __attribute__((visibility("default"))) const void* keithray_mpi_module(const char* version, const void*) {
    return std::strcmp(version, KEITHRAY_MODULE_VERSION) == 0 ? &kr::kModule : nullptr;
}

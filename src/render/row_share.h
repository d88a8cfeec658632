// The rows of a render shared between processes (MPI ranks): how they are dealt
// (row_owners), the rows one process owns and those it holds (rows_owned, rows_guarded), and
// RowShare, the exchange of per-row sums that keeps plans and estimates those of one process.
// A render region narrows a pass to its rows the same way (RenderState::active_rows).
#pragma once

#include <cstdint>
#include <vector>

#include "core/math.h"

namespace kr {

// The rows of an image shared between `count` processes, dealt in interleaved blocks: each
// process owns height/count rows (one more for the first height mod count processes), split
// into kRowBlocks contiguous blocks of near-equal size (some empty on short images), laid out
// block 0 of process 0, of 1, ..., of count - 1, then each one's block 1, and so on. A process
// holds its own rows and their neighbours (the 3x3 guard reads them): at most 2 kRowBlocks
// rows more than its share whatever the count, and the interleaving spreads every process's
// rows over the image, for balance. Everything that maps a row to its process or its place
// there (RowShare, app/cluster's gather, scatter and exchanges) reads row_owners.
constexpr int kRowBlocks = 32;
// The process owning each row of an image `height` rows high shared by `count` processes.
std::vector<int> row_owners(int count, int height);

// This process's share of the rows (row_owners): it samples and plans its rows, and holds the
// statistics of their neighbours too. The image-wide sums (of the plan, the noise rule, the
// estimated error) are taken per row, made known to every process by combine() and added in
// row order by each: the same plan and verdicts, bit for bit, as one process that owns every
// row (no RowShare).
class RowShare {
public:
    RowShare(int index, int count) : index_(index), count_(count) {}
    virtual ~RowShare() = default;
    int index() const { return index_; }
    int count() const { return count_; }
    // `values` holds `fields` numbers per row, rows in order, this process's own rows filled
    // in: replaces every other row's with the numbers of the process that owns it.
    virtual void combine(std::vector<double>& values, int fields) const = 0;

private:
    int index_, count_;
};

// The rows `share` gives this process, in order (every row without a share), and those its
// 3x3 guard reads: its own and their neighbours.
std::vector<int> rows_owned(const RowShare* share, int height);
std::vector<int> rows_guarded(const RowShare* share, int height);
// Those of process `index` of `count`.
std::vector<int> rows_owned(int index, int count, int height);
std::vector<int> rows_guarded(int index, int count, int height);

// The three sums of a pixel that the 3x3 guard reads (radiance_sum, luminance_sq_sum,
// sample_count): what a process of a shared render sends its neighbours of its rows.
inline constexpr uint64_t kGuardRowBytesPerPixel = sizeof(Color) + sizeof(double) + sizeof(uint32_t);

}  // namespace kr

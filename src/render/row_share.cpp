#include "render/row_share.h"

#include <algorithm>
#include <cstddef>

namespace kr {

std::vector<int> row_owners(int count, int height) {
    std::vector<int> owner(size_t(std::max(height, 0)));
    size_t y = 0;
    for (int64_t block = 0; block < kRowBlocks; ++block)
        for (int r = 0; r < count; ++r) {
            const int64_t share = height / count + (r < height % count);
            // Block `block` of the share's kRowBlocks near-equal blocks.
            const int64_t rows = (block + 1) * share / kRowBlocks - block * share / kRowBlocks;
            std::fill_n(owner.begin() + ptrdiff_t(y), rows, r);
            y += size_t(rows);
        }
    return owner;
}

std::vector<int> rows_owned(int index, int count, int height) {
    const std::vector<int> owner = row_owners(count, height);
    std::vector<int> rows;
    for (int y = 0; y < height; ++y)
        if (owner[size_t(y)] == index) rows.push_back(y);
    return rows;
}

std::vector<int> rows_guarded(int index, int count, int height) {
    const std::vector<int> owner = row_owners(count, height);
    std::vector<int> rows;
    const auto owns = [&](int y) { return y >= 0 && y < height && owner[size_t(y)] == index; };
    for (int y = 0; y < height; ++y)
        if (owns(y) || owns(y - 1) || owns(y + 1)) rows.push_back(y);
    return rows;
}

std::vector<int> rows_owned(const RowShare* share, int height) {
    return share ? rows_owned(share->index(), share->count(), height) : rows_owned(0, 1, height);
}

std::vector<int> rows_guarded(const RowShare* share, int height) {
    return share ? rows_guarded(share->index(), share->count(), height) : rows_guarded(0, 1, height);
}

}  // namespace kr

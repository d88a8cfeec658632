// The per-pass exchange of keithray under MPI on its own (docs/scaling.md): MPI_Allgatherv
// of the statistics the adaptive plan reads, 36 bytes per pixel (radiance sum, luminance
// square sum, sample count), each rank sending its 1/N. Prints each of 7 rounds' seconds
// at rank 0 (the first pays the buffers' first touch). Built and run by
// scripts/bench_mpi.sh exchange. Usage: bench_mpi_exchange WIDTH HEIGHT
#include <mpi.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <vector>

int main(int argc, char** argv) {
    MPI_Init(&argc, &argv);
    int ranks = 1, rank = 0;
    MPI_Comm_size(MPI_COMM_WORLD, &ranks);
    MPI_Comm_rank(MPI_COMM_WORLD, &rank);
    const size_t pixels = argc > 2 ? size_t(std::atol(argv[1])) * size_t(std::atol(argv[2])) : 512 * 512;
    const size_t share = pixels * 36 / size_t(ranks);
    std::vector<char> all(share * size_t(ranks), 1), mine(share, 2);
    std::vector<int> counts(static_cast<size_t>(ranks), int(share)), offsets(static_cast<size_t>(ranks));
    for (int r = 0; r < ranks; ++r) offsets[size_t(r)] = r * int(share);
    std::vector<double> seconds;
    for (int round = 0; round < 7; ++round) {
        MPI_Barrier(MPI_COMM_WORLD);
        const auto start = std::chrono::steady_clock::now();
        MPI_Allgatherv(mine.data(), int(share), MPI_BYTE, all.data(), counts.data(), offsets.data(), MPI_BYTE,
                       MPI_COMM_WORLD);
        seconds.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
    }
    if (rank == 0) {
        std::printf("np %d, %zu pixels, %.1f MB received per rank:", ranks, pixels,
                    double(share) * double(ranks - 1) * 1e-6);
        for (double s : seconds) std::printf(" %.4f", s);
        std::printf(" s\n");
    }
    MPI_Finalize();
}

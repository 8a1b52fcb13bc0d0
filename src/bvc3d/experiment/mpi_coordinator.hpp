#pragma once
// Trials over MPI ranks (bvc3d sweep under mpirun): rank 0 decides which groups remain and deals
// them out one at a time as ranks (and their threads) become free; every rank writes its trials'
// files to the shared output folder; rank 0 writes the summary. Results do not depend on the number
// of ranks or threads: every trial is seeded on its own and single-threaded.
#include <mpi.h>

#include <atomic>
#include <mutex>
#include <thread>

#include "bvc3d/experiment/experiment.hpp"

namespace bvc3d {

class MpiCoordinator : public Coordinator {
public:
    // MPI must be initialized with at least MPI_THREAD_SERIALIZED.
    MpiCoordinator(MPI_Comm comm, const std::atomic<bool>* stop);
    ~MpiCoordinator() override;

    bool is_root() const override { return rank_ == 0; }
    int rank() const { return rank_; }
    int size() const { return size_; }
    std::vector<std::size_t> agree(std::vector<std::size_t> pending) override;
    std::optional<std::size_t> next() override;
    void finish() override;

private:
    long long take();  // root: the next group, or -1
    void serve();      // root: answer requests until every other rank has finished

    MPI_Comm comm_;
    int rank_ = 0, size_ = 1;
    const std::atomic<bool>* stop_;
    std::mutex mpi_;  // MPI calls one at a time (MPI_THREAD_SERIALIZED)
    std::size_t n_ = 0;
    std::atomic<std::size_t> next_{0};
    std::thread server_;
};

}  // namespace bvc3d

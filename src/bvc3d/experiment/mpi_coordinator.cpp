#include "bvc3d/experiment/mpi_coordinator.hpp"

#include <chrono>

namespace bvc3d {

namespace {
constexpr int tag_request = 1, tag_reply = 2, tag_finished = 3;
}

MpiCoordinator::MpiCoordinator(MPI_Comm comm, const std::atomic<bool>* stop) : comm_(comm), stop_(stop) {
    MPI_Comm_rank(comm_, &rank_);
    MPI_Comm_size(comm_, &size_);
}

MpiCoordinator::~MpiCoordinator() {
    if (server_.joinable()) server_.join();
}

std::vector<std::size_t> MpiCoordinator::agree(std::vector<std::size_t> pending) {
    unsigned long long n = pending.size();
    MPI_Bcast(&n, 1, MPI_UNSIGNED_LONG_LONG, 0, comm_);
    std::vector<unsigned long long> buf(pending.begin(), pending.end());
    buf.resize(n);
    if (n) MPI_Bcast(buf.data(), static_cast<int>(n), MPI_UNSIGNED_LONG_LONG, 0, comm_);
    n_ = n;
    if (rank_ == 0 && size_ > 1) server_ = std::thread([this] { serve(); });
    return std::vector<std::size_t>(buf.begin(), buf.end());
}

long long MpiCoordinator::take() {
    if (stop_ && stop_->load()) return -1;
    const std::size_t i = next_.fetch_add(1);
    return i < n_ ? static_cast<long long>(i) : -1;
}

void MpiCoordinator::serve() {
    int finished = 0;
    while (finished < size_ - 1) {
        int flag = 0;
        MPI_Status st;
        {
            std::lock_guard lock(mpi_);
            MPI_Iprobe(MPI_ANY_SOURCE, MPI_ANY_TAG, comm_, &flag, &st);
        }
        if (!flag) {
            std::this_thread::sleep_for(std::chrono::milliseconds(1));
            continue;
        }
        std::lock_guard lock(mpi_);
        int dummy = 0;
        MPI_Recv(&dummy, 1, MPI_INT, st.MPI_SOURCE, st.MPI_TAG, comm_, MPI_STATUS_IGNORE);
        if (st.MPI_TAG == tag_request) {
            const long long g = take();
            MPI_Send(&g, 1, MPI_LONG_LONG, st.MPI_SOURCE, tag_reply, comm_);
        } else if (st.MPI_TAG == tag_finished) {
            ++finished;
        }
    }
}

std::optional<std::size_t> MpiCoordinator::next() {
    long long g = -1;
    if (rank_ == 0) {
        g = take();
    } else {
        std::lock_guard lock(mpi_);
        int dummy = 0;
        MPI_Send(&dummy, 1, MPI_INT, 0, tag_request, comm_);
        MPI_Recv(&g, 1, MPI_LONG_LONG, 0, tag_reply, comm_, MPI_STATUS_IGNORE);
    }
    return g < 0 ? std::nullopt : std::optional<std::size_t>(static_cast<std::size_t>(g));
}

void MpiCoordinator::finish() {
    if (rank_ != 0) {
        std::lock_guard lock(mpi_);
        int dummy = 0;
        MPI_Send(&dummy, 1, MPI_INT, 0, tag_finished, comm_);
    } else if (server_.joinable()) {
        server_.join();
    }
}

}  // namespace bvc3d

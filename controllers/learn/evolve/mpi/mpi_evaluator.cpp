// MPI evaluation (see mpi_evaluator.hpp).

#include "animrt/learn/evolve/mpi_evaluator.hpp"

#include <mpi.h>

#include <stdexcept>
#include <vector>

namespace animrt::evolve {
namespace {

// GaitMeasures travel as doubles; the layout is ours on both ends.
constexpr int kFields = 9;

void pack(const GaitMeasures& m, double* out) {
  out[0] = m.fell ? 1.0 : 0.0;
  out[1] = m.speed;
  out[2] = m.distance;
  out[3] = m.stride_length;
  out[4] = m.duty_factor;
  out[5] = m.energy_per_cycle;
  out[6] = m.sim_time;
  out[7] = static_cast<double>(m.steps);
  out[8] = m.max_tilt_deg;
}

GaitMeasures unpack(const double* in) {
  GaitMeasures m;
  m.fell = in[0] != 0.0;
  m.speed = in[1];
  m.distance = in[2];
  m.stride_length = in[3];
  m.duty_factor = in[4];
  m.energy_per_cycle = in[5];
  m.sim_time = in[6];
  m.steps = static_cast<long>(in[7]);
  m.max_tilt_deg = in[8];
  return m;
}

}  // namespace

MpiSession::MpiSession(int* argc, char*** argv) {
  int provided = 0;
  if (MPI_Init_thread(argc, argv, MPI_THREAD_FUNNELED, &provided) != MPI_SUCCESS) {
    throw std::runtime_error("MPI_Init_thread failed");
  }
  MPI_Comm_rank(MPI_COMM_WORLD, &rank_);
  MPI_Comm_size(MPI_COMM_WORLD, &size_);
}

MpiSession::~MpiSession() { MPI_Finalize(); }

bool MpiSession::broadcast(bool value) const {
  int flag = value ? 1 : 0;
  MPI_Bcast(&flag, 1, MPI_INT, 0, MPI_COMM_WORLD);
  return flag != 0;
}

MpiEvaluator::MpiEvaluator(const MpiSession& session, Evaluator& local)
    : rank_(session.rank()), size_(session.size()), local_(local) {}

int MpiEvaluator::workers() const {
  int total = 0;
  int mine = local_.workers();
  MPI_Allreduce(&mine, &total, 1, MPI_INT, MPI_SUM, MPI_COMM_WORLD);
  return total;
}

void MpiEvaluator::walk_all(std::span<const GaitFile* const> gaits, const WalkSettings& settings,
                            std::span<GaitMeasures> out) {
  const int n = static_cast<int>(gaits.size());
  // Rank r walks gaits r, r + size, r + 2 size, ...
  std::vector<const GaitFile*> mine;
  for (int i = rank_; i < n; i += size_) mine.push_back(gaits[static_cast<std::size_t>(i)]);
  std::vector<GaitMeasures> local(mine.size());
  local_.walk_all(mine, settings, local);

  std::vector<double> send(local.size() * kFields);
  for (std::size_t k = 0; k < local.size(); ++k) pack(local[k], &send[k * kFields]);
  std::vector<int> counts(static_cast<std::size_t>(size_));
  std::vector<int> displs(static_cast<std::size_t>(size_));
  int offset = 0;
  for (int r = 0; r < size_; ++r) {
    const int share = r < n ? (n - r + size_ - 1) / size_ : 0;
    counts[static_cast<std::size_t>(r)] = share * kFields;
    displs[static_cast<std::size_t>(r)] = offset;
    offset += share * kFields;
  }
  std::vector<double> all(static_cast<std::size_t>(offset));
  MPI_Allgatherv(send.data(), static_cast<int>(send.size()), MPI_DOUBLE, all.data(), counts.data(),
                 displs.data(), MPI_DOUBLE, MPI_COMM_WORLD);
  for (int r = 0; r < size_; ++r) {
    const double* block = all.data() + displs[static_cast<std::size_t>(r)];
    int k = 0;
    for (int i = r; i < n; i += size_, ++k) {
      out[static_cast<std::size_t>(i)] = unpack(block + k * kFields);
    }
  }
}

}  // namespace animrt::evolve

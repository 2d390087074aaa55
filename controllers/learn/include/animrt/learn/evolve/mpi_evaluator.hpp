#pragma once
// Distributed evaluation over MPI (target animrt_evolve_mpi; this header does
// not include mpi.h). Every rank runs the same search from the same seed, so
// every rank holds the same population; each walks its share of a batch
// (gait i on rank i mod size, with its own threads) and the measures are
// exchanged with MPI_Allgatherv, so every rank continues with identical
// results. Only rank 0 should write output.
//
//   mpirun -np 4 animrt evolve RUN.yaml --out GAIT.yaml --mpi
//   (as root: add --allow-run-as-root; more ranks than cores: --oversubscribe)

#include <memory>

#include "animrt/learn/evolve/evaluator.hpp"

namespace animrt::evolve {

// MPI_Init on first use (thread support: funneled); MPI_Finalize at exit.
class MpiSession {
 public:
  MpiSession(int* argc, char*** argv);
  ~MpiSession();
  MpiSession(const MpiSession&) = delete;
  MpiSession& operator=(const MpiSession&) = delete;
  int rank() const { return rank_; }
  int size() const { return size_; }
  // Rank 0's `value` on every rank (a collective: every rank calls it, in
  // the same order), e.g. a stop request only rank 0's dashboard receives.
  bool broadcast(bool value) const;

 private:
  int rank_ = 0;
  int size_ = 1;
};

class MpiEvaluator final : public Evaluator {
 public:
  // `local` walks this rank's share (e.g. a ThreadEvaluator).
  MpiEvaluator(const MpiSession& session, Evaluator& local);
  void walk_all(std::span<const GaitFile* const> gaits, const WalkSettings& settings,
                std::span<GaitMeasures> out) override;
  int workers() const override;

 private:
  int rank_;
  int size_;
  Evaluator& local_;
};

}  // namespace animrt::evolve

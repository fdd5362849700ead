// MultiObjectiveRegistration core: the evaluation backend interface (SPEC 6).
// The optimiser hands a backend whole batches: all solutions to evaluate in
// full, or all partial candidates of one parallel group for all solutions of
// a cluster. Candidates of one batch never share a tetrahedron of the same
// solution, so a backend may evaluate them in any order and at once.
#ifndef morea_EvaluationBackend_h
#define morea_EvaluationBackend_h

#include "morea/ParallelStructure.h"
#include "morea/TetrahedronObjectives.h"

#include <cstddef>
#include <memory>
#include <string>
#include <vector>

namespace morea
{
/** A parent solution with the points of one FOS element moved. */
struct PartialCandidate
{
  const DualMesh *   parent{ nullptr };
  const FosElement * element{ nullptr };
  const Vec3 *       source{ nullptr }; ///< new source positions, one per element point
  const Vec3 *       target{ nullptr }; ///< new target positions, one per element point
  /** Output: one entry per element->dependentTetrahedra, in that order. */
  TetrahedronValues * values{ nullptr };
};

class EvaluationBackend
{
public:
  virtual ~EvaluationBackend() = default;

  /** "cpu" or "cuda". */
  virtual std::string
  Name() const = 0;

  /** Per-tetrahedron values of whole solutions: values[i] gets one entry per
   *  tetrahedron of solutions[i]. */
  virtual void
  EvaluateSolutions(const std::vector<const DualMesh *> & solutions,
                    const std::vector<std::vector<TetrahedronValues> *> & values) = 0;

  /** The dependent tetrahedra of every candidate, each with its moved points. */
  virtual void
  EvaluatePartials(const std::vector<PartialCandidate> & candidates) = 0;
};

/** The CPU backend over `threads` threads (0: all hardware threads). */
std::unique_ptr<EvaluationBackend>
CreateCpuEvaluationBackend(const TetrahedronEvaluator & evaluator, std::size_t threads = 0);

/** Corners of tetrahedron `t` in a parent whose element points are replaced. */
void
CandidateCorners(const PartialCandidate & candidate, const Tetrahedron & t, Corners & source, Corners & target);
} // namespace morea

#endif

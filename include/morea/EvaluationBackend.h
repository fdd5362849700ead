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
#include <cstdint>
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

/** Work a backend has done since it was made (for benchmarks and logs). */
struct BackendStatistics
{
  std::uint64_t batches{ 0 };       ///< EvaluateSolutions and EvaluatePartials calls
  std::uint64_t tetrahedra{ 0 };    ///< tetrahedra evaluated (both directions each)
  double        samples{ 0.0 };     ///< sample points drawn, both directions
  double        seconds{ 0.0 };     ///< wall time inside the calls
  double        kernelSeconds{ 0.0 }; ///< device time of the kernels (CUDA only)
};

class EvaluationBackend
{
public:
  virtual ~EvaluationBackend() = default;

  const BackendStatistics &
  Statistics() const
  {
    return m_Statistics;
  }

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

protected:
  BackendStatistics m_Statistics;
};

/** The CPU backend over `threads` threads (0: all hardware threads). */
std::unique_ptr<EvaluationBackend>
CreateCpuEvaluationBackend(const TetrahedronEvaluator & evaluator, std::size_t threads = 0);

/** How the CUDA backend interpolates images with at most 4 channels. */
enum class CudaInterpolation
{
  Exact,  ///< software trilinear: agrees with the CPU backend to rounding (the default)
  Texture ///< the texture units' filtering (9-bit weights): faster, agrees less closely
};

/** The CUDA backend on device 0 (`threads` host threads pack and unpack the
 *  batches). Throws morea::Error when the build has no CUDA or no device is
 *  present, and names out-of-memory as such. */
std::unique_ptr<EvaluationBackend>
CreateCudaEvaluationBackend(const TetrahedronEvaluator & evaluator, std::size_t threads = 0,
                            CudaInterpolation interpolation = CudaInterpolation::Exact);

enum class BackendChoice
{
  Cpu,
  Cuda,        ///< exact (software) trilinear interpolation, as the CPU
  CudaTexture, ///< hardware-filtered interpolation: faster, within about 1e-4 of the CPU
  Auto         ///< CUDA (exact) when a device is present, else the CPU
};

/** "cpu", "cuda", "cuda-texture" or "auto"; anything else is an error. */
BackendChoice
ParseBackendChoice(const std::string & name);

/** The one place that picks the platform. */
std::unique_ptr<EvaluationBackend>
CreateEvaluationBackend(BackendChoice choice, const TetrahedronEvaluator & evaluator, std::size_t threads = 0);

/** Corners of tetrahedron `t` on one side of a mesh whose points `moved` are
 *  replaced by `replacements` (one per moved point, in the same order). */
Corners
CornersWithReplacedPoints(const Tetrahedron & t, const std::vector<Vec3> & points,
                          const std::vector<std::uint32_t> & moved, const Vec3 * replacements);

/** Corners of tetrahedron `t` in a parent whose element points are replaced. */
void
CandidateCorners(const PartialCandidate & candidate, const Tetrahedron & t, Corners & source, Corners & target);
} // namespace morea

#endif

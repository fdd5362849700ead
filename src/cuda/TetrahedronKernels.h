// Launchers of the CUDA tetrahedron kernels, in plain C++ types so that the
// backend's host code and nvcc share no headers beyond this one.
#ifndef morea_cuda_TetrahedronKernels_h
#define morea_cuda_TetrahedronKernels_h

#include <cstddef>
#include <cstdint>

namespace morea::cuda
{
/** A multi-channel volume in device memory, channels interleaved per voxel. */
struct VolumeView
{
  const float * data{ nullptr };
  int           size[3]{ 0, 0, 0 };
  double        origin[3]{ 0.0, 0.0, 0.0 };
  double        spacing[3]{ 1.0, 1.0, 1.0 };
  double        inverseSpacing[3]{ 1.0, 1.0, 1.0 };
  int           channels{ 0 };
};

/** How the kernels interpolate the images. */
enum class Interpolation
{
  Exact,   ///< trilinear in software from 16-byte loads, weights as on the CPU (agrees to rounding)
  Texture  ///< the texture units' trilinear filtering (9-bit weights: faster, not bit-comparable)
};

/** The same volume with its channels padded to 4 (float4 per voxel), in
 *  global memory for Exact and as a texture object for Texture. */
struct PackedVolumeView
{
  const void *       data{ nullptr };   ///< float4 per voxel
  unsigned long long texture{ 0 };      ///< cudaTextureObject_t
  int                size[3]{ 0, 0, 0 };
  double             origin[3]{ 0.0, 0.0, 0.0 };
  double             spacing[3]{ 1.0, 1.0, 1.0 };
  double             inverseSpacing[3]{ 1.0, 1.0, 1.0 };
};

/** Everything a tetrahedron's evaluation reads besides its corners. */
struct EvaluationConstants
{
  VolumeView      moving;           ///< the source mesh lives here
  VolumeView      fixed;            ///< the target mesh lives here
  const double *  guidanceWeights{ nullptr };
  int             structures{ 0 };
  double          guidanceRadius{ 0.0 };
  double          samplingRate{ 1.0 };
  double          voxelVolume{ 1.0 };
  const double *  elasticity{ nullptr };       ///< per tetrahedron, or null (all 1)
  const double *  referenceVolumes{ nullptr }; ///< signed base volume per tetrahedron
  double          volumeFraction{ 0.0 };
  /** Set when the images have at most 4 channels: the fast kernels use these. */
  bool             packed{ false };
  Interpolation    interpolation{ Interpolation::Exact };
  PackedVolumeView packedMoving, packedFixed;
};

/** Per work item: magnitude, fold value, folded count. */
constexpr int ItemValues = 3;
/** Per work item and direction: intensity sum, guidance sum, samples. */
constexpr int DirectionValues = 3;
/** Corners of one work item: source 4 x 3 then target 4 x 3 doubles. */
constexpr int ItemCorners = 24;

/** Copies the Sobol direction numbers (4 x 32) to the device; once per process. */
void
UploadSobolDirections(const std::uint32_t * directions);

/** Evaluates `items` tetrahedra: `corners` (items x 24 doubles) and
 *  `tetrahedra` (items indices) on the device; writes `itemOut`
 *  (items x ItemValues) and `directionOut` (items x 2 x DirectionValues).
 *  Asynchronous on `stream` (a cudaStream_t); checks the launch. */
void
LaunchEvaluateTetrahedra(const EvaluationConstants & constants, const double * corners,
                         const std::uint32_t * tetrahedra, std::size_t items, double * itemOut,
                         double * directionOut, void * stream);
} // namespace morea::cuda

#endif

// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
// Launchers of the CUDA tetrahedron kernels, in plain C++ types so that the
// backend's host code and nvcc share no headers beyond this one.
#ifndef morea_cuda_TetrahedronKernels_h
#define morea_cuda_TetrahedronKernels_h

#include <cstddef>
#include <cstdint>

namespace morea_core::cuda
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
  Texture  ///< the texture units' filtering (8-bit weights across x and y: faster, not bit-comparable)
};

/** Structures whose distances the texture path reads. Each has textures
 *  of its own, read only near its contour (nearBlocks), so the number costs
 *  only the fetches near contours, the textures' memory and the mask's
 *  bits; with more, the backend takes the exact kernels and says why
 *  (EvaluationBackend::PathNote). */
constexpr int MaxTextureStructures = 16;

/** Bits per block of PackedVolumeView::nearBlocks for `structures`
 *  structures: 4 (two blocks per byte) up to 4 structures, 8 up to 8, else
 *  16. The fewest that hold them: the mask stays small enough for L1 (9 KB
 *  at 4 bits for the paper's abdomen pair). */
constexpr int
NearBlockBits(int structures)
{
  return structures <= 4 ? 4 : (structures <= 8 ? 8 : 16);
}

/** The images as the fast kernels read them. Exact (at most 4 channels):
 *  channels padded to 4, float4 per voxel in global memory. Texture (at
 *  most MaxTextureStructures structures): the intensity as 16-bit
 *  normalised texels (2 bytes: small footprint, many samples per cache
 *  line) and each structure's distance map as textures of its own, read
 *  only near its contour. */
struct PackedVolumeView
{
  const void *       data{ nullptr };            ///< Exact: float4 per voxel
  unsigned long long intensityTexture{ 0 };      ///< Texture: cudaTextureObject_t, slice pairs (SlicePairTrilinear)
  /** Texture: the smallest distance over all structures as one float
   *  texture (cudaTextureObject_t; 0 without structures), read by the
   *  set-up kernel at each tetrahedron's centre. Its interpolated value is
   *  never above the smallest of the structures' interpolated distances
   *  (trilinear weights are convex, the minimum concave), so a tetrahedron
   *  it finds far from every contour is; one fetch instead of one per
   *  structure. */
  unsigned long long nearestDistanceTexture{ 0 };
  /** Texture: per structure its distances as slice pairs of 16-bit
   *  normalised texels (SlicePairTrilinear), times distanceScales[g] in mm
   *  (the largest distance, so steps of 1/65535 of it): what the
   *  sampling kernel reads, in one filtering pass at the layer it already
   *  found for the intensity, where a float 3D texture took two. On an
   *  H100, early generations' kernels served 9.77e10 samples per second
   *  against 9.58e10, with the guidance closer to the CPU's (the weight
   *  along z in single precision). 0 past distanceMaps. */
  unsigned long long distancePairTextures[MaxTextureStructures]{};
  float              distanceScales[MaxTextureStructures]{};
  int                distanceMaps{ 0 }; ///< Texture: structures (0: none)
  /** Texture: per block of NearBlockSize^3 texels (x fastest)
   *  NearBlockBits(distanceMaps) bits, bit g set where a sample whose
   *  trilinear footprint starts in the block may lie within the guidance
   *  radius of structure g's contour: the smallest distance of the texels it
   *  can read is below the radius (an interpolated value is never below its
   *  texels' minimum). At 4 bits block b takes the low half of byte b / 2
   *  for even b, the high half for odd b; at 16 bits a little-endian
   *  16-bit word. Null without structures. Bits rather than a byte per
   *  block keep the mask small enough for L1 (9 KB for the paper's abdomen
   *  pair); with one bit per block for all structures, late generations'
   *  kernels on an H100 took 0.0898 s per generation against 0.0911 s with
   *  bytes. */
  const std::uint8_t * nearBlocks{ nullptr };
  int                  blocks[3]{ 0, 0, 0 };
  int                size[3]{ 0, 0, 0 };
  double             origin[3]{ 0.0, 0.0, 0.0 };
  double             spacing[3]{ 1.0, 1.0, 1.0 };
  double             inverseSpacing[3]{ 1.0, 1.0, 1.0 };
};

/** Edge of PackedVolumeView::nearBlocks' blocks, in texels
 *  (morea_core::NearContourBlocks::BlockSize). */
constexpr int NearBlockSize = 4;

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
  /** The rigidity term (morea/RigidityTerm.h): per tetrahedron its weight
   *  and 9 numbers of the base edge matrix's inverse; null without rigid structures. */
  const double *  rigidWeights{ nullptr };
  const double *  rigidInverseEdges{ nullptr };
  /** The rigid strain limit's constraint: per tetrahedron its base volume
   *  where it holds (0 elsewhere), null without a limit; the limit squared. */
  const double *  rigidLimitVolumes{ nullptr };
  double          rigidStrainLimitSquared{ 0.0 };
  const double *  referenceVolumes{ nullptr }; ///< signed base volume per tetrahedron
  std::uint32_t   tetrahedra{ 0 };             ///< of the mesh
  double          volumeFraction{ 0.0 };
  /** Set when packedMoving and packedFixed hold the images: the exact path
   *  with at most 4 channels, the texture path with at most
   *  MaxTextureStructures structures. Otherwise `moving` and `fixed` do
   *  (the generic exact kernel, any number of channels). */
  bool             packed{ false };
  Interpolation    interpolation{ Interpolation::Exact };
  PackedVolumeView packedMoving, packedFixed;
  /** Texture path: samples per chunk (one warp each), a multiple of 32.
   *  A chunk waits for three dependent loads (its task, where the task's
   *  chunks begin, the task's corners) before its first fetch; longer chunks
   *  spread that wait over more samples. On an H100 the sampling kernel
   *  served 7.26e10 samples per second with 128, 8.02e10 with 256 and
   *  8.33e10 with 512. */
  std::uint32_t chunkSamples{ 512 };
  /** The guidance weights again, by value, for the texture kernels. */
  float textureGuidanceWeights[MaxTextureStructures]{};
};

/** A batch of partial candidates as the device sees it: each candidate is a
 *  parent (a slot in `parents`) with the points of one element (a slot in
 *  the element tables) moved to new positions. */
struct CandidateBatch
{
  const std::uint32_t * tetrahedra{ nullptr };  ///< the mesh: 4 point indices per tetrahedron
  std::uint32_t         points{ 0 };            ///< points per mesh side
  const double *        parents{ nullptr };     ///< per parent slot: source then target, points x 3
  const std::uint32_t * elementPointOffsets{ nullptr };       ///< per element slot, plus one
  const std::uint32_t * elementPoints{ nullptr };
  const std::uint32_t * elementTetrahedronOffsets{ nullptr }; ///< per element slot, plus one
  const std::uint32_t * elementTetrahedra{ nullptr };         ///< dependent tetrahedra
  const std::uint32_t * candidateElement{ nullptr };          ///< element slot per candidate
  const std::uint32_t * candidateParent{ nullptr };           ///< parent slot per candidate
  const std::uint32_t * candidateMoved{ nullptr };            ///< first moved point per candidate
  const std::uint64_t * candidateFirstItem{ nullptr };        ///< per candidate, plus one (= items)
  std::size_t           candidates{ 0 };
  /** The corner gathering and the refusal screen take candidates
   *  [firstCandidate, candidates) only: a batch may go up in ranges. */
  std::size_t           firstCandidate{ 0 };
  const double *        moved{ nullptr }; ///< moved point m: source at 6 m, target at 6 m + 3
};

/** Per work item: magnitude, fold value, folded count. */
constexpr int ItemValues = 3;
/** Per work item and direction: intensity sum, guidance sum, samples. */
constexpr int DirectionValues = 3;
/** Corners of one work item: source 4 x 3 then target 4 x 3 doubles. */
constexpr int ItemCorners = 24;
/** Per candidate: its items' values summed, in TetrahedronValues' order. */
constexpr int CandidateSumValues = 6;

/** Per item of a batch (`itemSkip` bytes): sampled, or not sampled since its
 *  values go unused (a candidate left folded: no sample counts either), or
 *  not sampled since a refusal bound skipped its candidate (its sample
 *  counts stay, its intensity and guidance sums are 0). */
enum ItemSkip : std::uint8_t
{
  ItemSampled = 0,
  ItemUnused = 1,
  ItemBoundSkipped = 2
};

/** Copies the Sobol direction numbers (4 x 32) to the device; once per process. */
void
UploadSobolDirections(const std::uint32_t * directions);

/** Which candidates need no values: those left folded by the fold checks
 *  (`outcome`, per candidate and side, SideFolded | SideRepaired) whose
 *  `skipIfFolded` byte is set, as the CPU backend skips them. Both null:
 *  every candidate is evaluated. */
struct FoldedCandidateSkip
{
  const std::uint8_t * skipIfFolded{ nullptr }; ///< per candidate
  const std::uint8_t * outcome{ nullptr };      ///< per candidate and side
};

/** Writes the corners (items x ItemCorners) and tetrahedron index of every
 *  dependent tetrahedron of every candidate of `batch`, in candidate order:
 *  the parents' points with each element's points replaced, as
 *  CandidateCorners does on the host; `itemSkip` (items bytes) is ItemUnused
 *  for the items of a candidate that `skip` leaves out, else ItemSampled.
 *  Asynchronous on `stream`. */
void
LaunchGatherCandidateCorners(const CandidateBatch & batch, std::size_t items, const FoldedCandidateSkip & skip,
                             double * corners, std::uint32_t * tetrahedra, std::uint8_t * itemSkip, void * stream);

/** Writes the corners (ItemCorners each) and tetrahedron index of every
 *  tetrahedron of `count` whole solutions, item s * tetrahedraPerSolution + t
 *  for solution s's tetrahedron t, from `solutions` (per solution its
 *  source points, then its target points, points x 3 doubles each) and
 *  `mesh` (4 point indices per tetrahedron), as the host packs them.
 *  Asynchronous on `stream`. */
void
LaunchGatherSolutionCorners(const double * solutions, std::size_t count, const std::uint32_t * mesh,
                            std::size_t tetrahedraPerSolution, std::size_t points, double * corners,
                            std::uint32_t * tetrahedra, void * stream);

/** Per candidate of [batch.firstCandidate, batch.candidates): the sum over
 *  its items (in order, from 0, as the host adds them) of their values as
 *  the host unpacks them from `itemValues` and `directionValues`, to
 *  sums[c * CandidateSumValues ...] (magnitude, intensity, guidance,
 *  samples, fold value, folded). Asynchronous on `stream`. */
void
LaunchSumCandidateValues(const CandidateBatch & batch, const double * itemValues, const double * directionValues,
                         double * sums, void * stream);

/** Copies parent i of `staged` (count x perParent doubles) to slot
 *  slots[i] of `store` (perParent doubles per slot). Asynchronous on
 *  `stream`. */
void
LaunchScatterParents(const double * staged, const std::uint32_t * slots, std::size_t count, std::size_t perParent,
                     double * store, void * stream);

/** Evaluates `items` tetrahedra with the exact (software) interpolation:
 *  `corners` (items x 24 doubles) and `tetrahedra` (items indices) on the
 *  device; writes `itemOut` (items x ItemValues) and `directionOut`
 *  (items x 2 x DirectionValues). Items are sampled as their `itemSkip`
 *  byte says (null: all).
 *  Asynchronous on `stream` (a cudaStream_t); checks the launch. */
void
LaunchEvaluateTetrahedra(const EvaluationConstants & constants, const double * corners,
                         const std::uint32_t * tetrahedra, const std::uint8_t * itemSkip, std::size_t items,
                         double * itemOut, double * directionOut, void * stream);

/** The texture path (packed images, Interpolation::Texture), built for
 *  throughput in two steps around one synchronisation. Step 1, one thread
 *  per tetrahedron: seeds, sample counts, corners in texel coordinates,
 *  per-item values (`itemOut`) and the split of every direction's samples
 *  into chunks of `chunkSamples`; CopyTextureChunkCount copies the number
 *  of chunks to the host. Step 2, one warp per chunk in single precision,
 *  then the chunks' sums in a fixed order (deterministic): `directionOut`.
 *  Large and small tetrahedra thus load the GPU evenly. */
/** Bytes of `workspace` step 1 needs for `items` tetrahedra. */
std::size_t
TexturePrepareWorkspaceBytes(std::size_t items);

/** Bytes of `chunkWorkspace` step 2 needs for `chunks` chunks. */
std::size_t
TextureChunkWorkspaceBytes(std::size_t chunks);

/** The order in which step 2 takes a part's items, where the batch's
 *  layout gives it: item j of candidate c (c in [firstCandidate,
 *  endCandidate), its items from candidateFirstItem[c] - partFirstItem)
 *  goes to place slots[2 c] + j slots[2 c + 1]. Null `slots`: step 1 sorts
 *  the items by tetrahedron instead (stable). */
struct ItemSchedule
{
  const std::uint32_t * slots{ nullptr };
  const std::uint64_t * candidateFirstItem{ nullptr }; ///< per candidate, plus one
  std::size_t           firstCandidate{ 0 };
  std::size_t           endCandidate{ 0 };
  std::uint64_t         partFirstItem{ 0 };
};

/** Step 1; an item is sampled as its `itemSkip` byte says (null: all). */
void
LaunchPrepareTexture(const EvaluationConstants & constants, const double * corners, const std::uint32_t * tetrahedra,
                     const std::uint8_t * itemSkip, std::size_t items, const ItemSchedule & schedule,
                     void * workspace, double * itemOut, void * stream);

/** Queues the copy of the number of chunks step 1 found for `items` into
 *  `totalChunks` (pinned host memory) on `stream`, which must be ordered
 *  after step 1. Any stream: on the one that runs step 2, the copy waited
 *  behind other streams' transfers from the device, and step 2 with it. */
void
CopyTextureChunkCount(std::size_t items, const void * workspace, std::uint32_t * totalChunks, void * stream);

/** Step 2 for at most `chunkCapacity` chunks (`chunkWorkspace` sized for
 *  them): the number step 1 found is read on the device, so that the host
 *  need not wait for it. Where it is larger (step 1's `totalChunks` says
 *  so), the sums are wrong: call again with room for all. */
void
LaunchSampleTexture(const EvaluationConstants & constants, std::size_t items, void * workspace,
                    std::size_t chunkCapacity, void * chunkWorkspace, double * directionOut, void * stream);

/** Samples chunks of the texture path one by one: entry i of `list` (4
 *  integers: item, direction, the chunk's place among the direction's
 *  chunks, unused) names a chunk of an item whose corners `corners` holds
 *  (items x ItemCorners); its intensity and guidance sums go to
 *  chunkSums[2 i] and [2 i + 1], as step 2 computes them. A direction's value
 *  is then the sum of its chunks' in order, from 0. Asynchronous on `stream`. */
void
LaunchSampleListedChunks(const EvaluationConstants & constants, const double * corners, const std::uint32_t * list,
                         std::size_t entries, double * chunkSums, void * stream);

/** Copies the Sobol direction numbers to the texture kernels' module. */
void
UploadTextureSobolDirections(const std::uint32_t * directions);
} // namespace morea_core::cuda

#endif

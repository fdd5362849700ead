// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
// The texture-interpolation path of the tetrahedron evaluation, built for
// throughput. Work that is the same for all samples of a tetrahedron (the
// seed hash, Sobol shifts, sample count, corners in texel coordinates) runs
// once per tetrahedron in a set-up kernel, one thread each, instead of once
// per lane; the sampling kernel then works in single precision with few
// registers, so that enough warps are resident to hide the texture latency.
// A tetrahedron's samples are split into chunks of a few hundred, one warp
// each: tetrahedra differ in size by orders of magnitude, and one warp per
// tetrahedron left most of the GPU idle while the largest ones finished.
// Sample points, sample counts and per-item values are those of the exact
// path; only the interpolation weights across x and y (8 fraction bits in
// the texture units), the 16-bit intensity texels and the single-precision
// arithmetic differ. Intensities are read as slice pairs (SlicePairTrilinear).
// Each guidance structure (up to MaxTextureStructures) has slice pairs of its
// own, read only where a per-block mask says its contour may be within the
// radius; the sampling kernels come in instances for 3, 4, 8 and 16
// structures (WithStructureSlots).
#include "TetrahedronKernels.h"

#include "DeviceMemory.h"
#include "TetrahedronDevice.cuh"

#include "morea_core/SampleCosets.h"

#include <cub/device/device_radix_sort.cuh>
#include <cub/device/device_scan.cuh>

#include <algorithm>
#include <array>
#include <cstdint>
#include <type_traits>

namespace morea_core::cuda
{
namespace
{
using namespace device;

__constant__ std::uint32_t c_SobolDirections[4 * 32];
/** Per lane the part of its samples' Sobol state that depends on the lane
 *  only (see SobolLaneState), without the digital shift: one 16-byte load
 *  per chunk instead of twenty masked XORs. */
__device__ uint4 g_LaneSobol[32];

/** Lanes of a whole chunk of 512 samples take spatially close points: each
 *  row of 32 is one coset of an index subspace W chosen for the aligned
 *  block of 2^9 to 2^14 samples the chunk lies in (morea/SampleCosets.h,
 *  which also says which block and cosets a chunk takes). The points are the
 *  CPU's; only the order in which they are added differs. On an H100, one
 *  W for blocks of 2^9 served 9.00e10 samples per second against 8.46e10
 *  with consecutive lanes; in larger tetrahedra its rows spread further, and
 *  a W for each block size served 9.01e10 against 8.92e10 (early
 *  generations, cuda/early-h100-block-cosets.txt). */
constexpr std::uint32_t CosetRows = CosetRowsPerChunk;
/** Per block size and lane its element of W as a Sobol state part (without
 *  the shift). */
__device__ uint4 g_CosetLaneSobol[CosetLevels][32];
/** Per block size the state parts of the complement's basis vectors: the
 *  row after coset r adds the one indexed by ctz(r + 1). */
__constant__ uint4 c_CosetRowSteps[CosetLevels][MaxCosetRowBits];

/** One direction of one tetrahedron, ready to sample. */
struct alignas(16) SampleTask
{
  float         from[12];    ///< sampled tetrahedron, texel coordinates of its image: corner 0, then
                             ///< corners 1-3 minus corner 0
  float         to[12];      ///< mapped tetrahedron, the same in texel coordinates of the other image
  std::uint32_t shift[4];    ///< Sobol digital shifts
  std::uint32_t samples;     ///< number of samples
  std::uint32_t nearContour; ///< 0 when no sample can lie within the guidance radius of a contour
  std::uint32_t padding[2];
};
static_assert(sizeof(SampleTask) == 128, "a task is one 128-byte line");

constexpr int           PrepareThreads = 128;
/** The sampling kernel's blocks: 40 warps per multiprocessor (48 registers
 *  each), in blocks as large as that allows, since a block's warps take
 *  consecutive chunks of the schedule and share its texels in the
 *  multiprocessor's cache. On an H100 (20 early generations of the paper's
 *  configuration, samples per second in kernels, in turns): 2 blocks of 20
 *  warps 1.132e11, 4 of 10 1.129e11, 5 of 8 1.124e11, 2 of 16 (32 warps)
 *  1.091e11; in another lease 10 blocks of 4 warps 1.013e11 against
 *  1.122e11 for 5 of 8. Against 4 blocks of 8 warps (32 warps, 54
 *  registers) 5 of 8 served 1.009 times the samples per second. */
constexpr int           SampleWarpsPerBlock = 20;
constexpr int           SampleBlocksPerMultiprocessor = 2;

/** Step 1's workspace, 256-byte aligned parts. Tasks are numbered 2 item +
 *  direction; the schedule is the order in which warps take their chunks:
 *  tasks grouped by tetrahedron (an ItemSchedule, or a stable sort), so
 *  that the warps running at one time sample the same tetrahedron of many
 *  solutions of the batch, which lies in about the same place of both
 *  images, and find its texels in the caches. On an H100 this took the L1
 *  hit rate from 52 to 65 % and the kernel time down by a quarter (L2
 *  throughput had been the limit). */
struct PrepareWorkspace
{
  SampleTask *    tasks;
  std::uint32_t * chunkCounts;    ///< per task
  std::uint32_t * scheduleCounts; ///< chunkCounts in schedule order
  std::uint32_t * scheduleEnds;   ///< inclusive running sum of scheduleCounts
  std::uint32_t * taskFirstChunk; ///< per task: its first chunk in the schedule
  std::uint32_t * itemIndex;      ///< 0, 1, ... (the sort's values)
  std::uint32_t * sortedKeys;     ///< the sorted tetrahedron indices (unused)
  std::uint32_t * sortedItems;    ///< items in schedule order
  void *          scratch;        ///< the scan's or the sort's temporary storage
  std::size_t     scratchBytes;
};

std::size_t
Aligned(std::size_t bytes)
{
  return (bytes + 255) / 256 * 256;
}

std::size_t
ScratchBytes(std::size_t items)
{
  std::size_t scan = 0, sort = 0;
  Check(cub::DeviceScan::InclusiveSum(nullptr, scan, static_cast<const std::uint32_t *>(nullptr),
                                      static_cast<std::uint32_t *>(nullptr), static_cast<int>(2 * items)),
        "sizing the chunk scan");
  Check(cub::DeviceRadixSort::SortPairs(nullptr, sort, static_cast<const std::uint32_t *>(nullptr),
                                        static_cast<std::uint32_t *>(nullptr),
                                        static_cast<const std::uint32_t *>(nullptr),
                                        static_cast<std::uint32_t *>(nullptr), static_cast<int>(items)),
        "sizing the schedule sort");
  return scan > sort ? scan : sort;
}

PrepareWorkspace
Partition(void * workspace, std::size_t items)
{
  const std::size_t tasks = 2 * items;
  auto *            base = static_cast<unsigned char *>(workspace);
  const auto        take = [&base](std::size_t count) {
    auto * part = reinterpret_cast<std::uint32_t *>(base);
    base += Aligned(count * sizeof(std::uint32_t));
    return part;
  };
  PrepareWorkspace w;
  w.tasks = reinterpret_cast<SampleTask *>(base);
  base += Aligned(tasks * sizeof(SampleTask));
  w.chunkCounts = take(tasks);
  w.scheduleCounts = take(tasks);
  w.scheduleEnds = take(tasks);
  w.taskFirstChunk = take(tasks);
  w.itemIndex = take(items);
  w.sortedKeys = take(items);
  w.sortedItems = take(items);
  w.scratch = base;
  w.scratchBytes = ScratchBytes(items);
  return w;
}

std::size_t
WorkspaceBytes(std::size_t items)
{
  const std::size_t tasks = 2 * items;
  return Aligned(tasks * sizeof(SampleTask)) + 4 * Aligned(tasks * sizeof(std::uint32_t)) +
         3 * Aligned(items * sizeof(std::uint32_t)) + ScratchBytes(items);
}

/** Texel coordinates (centres at +0.5) of corner 0, then the edges from
 *  corner 0 to corners 1-3 in texels: a sample point is then corner 0 plus
 *  three multiply-adds per axis. Along z the coordinate is the slice-pair
 *  coordinate, another half texel up (SlicePairTrilinear), so that no lane
 *  adds it per fetch. Clamping to the image is left to the texture's clamp
 *  addressing, which gives the edge voxel's value outside, as the exact
 *  path's clamped coordinates do. */
__device__ void
TexelCorners(const PackedVolumeView & image, const double c[12], float out[12])
{
#pragma unroll
  for (int a = 0; a < 3; ++a)
  {
    out[a] = static_cast<float>((c[a] - image.origin[a]) * image.inverseSpacing[a] + (a == 2 ? 1.0 : 0.5));
#pragma unroll
    for (int i = 1; i < 4; ++i)
      out[3 * i + a] = static_cast<float>((c[3 * i + a] - c[a]) * image.inverseSpacing[a]);
  }
}

__device__ void
PrepareDirection(const EvaluationConstants & k, const double from[12], const double to[12],
                 const PackedVolumeView & fromImage, const PackedVolumeView & toImage, SampleTask & task)
{
  task.samples = static_cast<std::uint32_t>(SampleCount(k.samplingRate, k.voxelVolume, from));
  SobolShifts(TetrahedronSeed(from), task.shift);
  TexelCorners(fromImage, from, task.from);
  TexelCorners(toImage, to, task.to);

  // Guidance counts only samples whose distance (in the sampled image) is
  // below the radius. The interpolated distance map changes by at most 1 per
  // mm along each axis (2 per mm in any direction, with room to spare), so a
  // tetrahedron whose centre is farther than radius + 2 x (its largest
  // centre-corner distance) + a rounding margin has no such sample.
  task.nearContour = 0;
  if (fromImage.distanceMaps == 0)
    return;
  double centre[3] = { 0.0, 0.0, 0.0 }, reach = 0.0, spacing = 0.0;
  for (int a = 0; a < 3; ++a)
  {
    centre[a] = 0.25 * (from[a] + from[3 + a] + from[6 + a] + from[9 + a]);
    spacing = fmax(spacing, fromImage.spacing[a]);
  }
  for (int i = 0; i < 4; ++i)
  {
    const double x = from[3 * i] - centre[0], y = from[3 * i + 1] - centre[1], z = from[3 * i + 2] - centre[2];
    reach = fmax(reach, sqrt(x * x + y * y + z * z));
  }
  float t[3];
  for (int a = 0; a < 3; ++a)
    t[a] = static_cast<float>((centre[a] - fromImage.origin[a]) * fromImage.inverseSpacing[a]) + 0.5f;
  // The smallest distance over all structures, interpolated: never above
  // the smallest interpolated distance (PackedVolumeView::nearestDistanceTexture).
  const double nearest = static_cast<double>(
    tex3D<float>(static_cast<cudaTextureObject_t>(fromImage.nearestDistanceTexture), t[0], t[1], t[2]));
  const double margin = 0.02 * spacing + 1e-4 * fabs(nearest);
  task.nearContour = nearest - 2.0 * reach - margin < k.guidanceRadius ? 1u : 0u;
}

/** A block's corners and tasks pass through shared memory, so that they
 *  move as whole lines: each thread read its item's 192 bytes of corners
 *  and wrote its 256 bytes of tasks alone, and two thirds of the sectors
 *  the kernel moved were excess (Nsight Compute, one H100). The strides are
 *  padded so that a warp's 8- and 16-byte accesses fall on distinct banks. */
constexpr int CornerStride = ItemCorners + 1;                          ///< doubles per item
constexpr int TaskQuads = static_cast<int>(sizeof(SampleTask) / sizeof(float4)); ///< 16-byte words per task
constexpr int TaskStride = 2 * TaskQuads + 1;                          ///< 16-byte words per item
union PrepareStage
{
  double corners[PrepareThreads * CornerStride];
  float4 tasks[PrepareThreads * TaskStride];
};

__global__ void __launch_bounds__(PrepareThreads)
PrepareTextureTasks(EvaluationConstants k, const double * __restrict__ corners,
                    const std::uint32_t * __restrict__ tetrahedra, const std::uint8_t * __restrict__ itemSkip,
                    std::size_t items, SampleTask * tasks, std::uint32_t * chunkCounts, std::uint32_t * itemIndex,
                    double * itemOut)
{
  __shared__ PrepareStage stage;
  const std::size_t first = static_cast<std::size_t>(blockIdx.x) * PrepareThreads;
  const int         local = static_cast<int>(threadIdx.x);
  const int         count = static_cast<int>(min(items - first, static_cast<std::size_t>(PrepareThreads)));
  const double *    blockCorners = corners + first * ItemCorners;
  for (int i = local; i < count * ItemCorners; i += PrepareThreads)
    stage.corners[(i / ItemCorners) * CornerStride + i % ItemCorners] = blockCorners[i];
  __syncthreads();
  double source[12], target[12];
  if (local < count)
  {
#pragma unroll
    for (int i = 0; i < 12; ++i)
    {
      source[i] = stage.corners[local * CornerStride + i];
      target[i] = stage.corners[local * CornerStride + 12 + i];
    }
  }
  __syncthreads(); // the stage now takes the tasks
  if (local < count)
  {
    const std::size_t item = first + local;
    // A skipped item gets no chunks; one whose values go unused no samples
    // either, one a refusal bound skipped keeps its count (ItemSkip).
    const std::uint8_t skip = itemSkip != nullptr ? itemSkip[item] : ItemSampled;
    SampleTask &       forward = *reinterpret_cast<SampleTask *>(stage.tasks + local * TaskStride);
    SampleTask &       backward = *reinterpret_cast<SampleTask *>(stage.tasks + local * TaskStride + TaskQuads);
    PrepareDirection(k, source, target, k.packedMoving, k.packedFixed, forward);
    PrepareDirection(k, target, source, k.packedFixed, k.packedMoving, backward);
    if (skip == ItemUnused)
      forward.samples = backward.samples = 0u;
    const auto chunksOf = [&](std::uint32_t samples) {
      return skip == ItemSampled ? (samples + k.chunkSamples - 1) / k.chunkSamples : 0u;
    };
    reinterpret_cast<uint2 *>(chunkCounts)[item] = make_uint2(chunksOf(forward.samples), chunksOf(backward.samples));
    if (itemIndex != nullptr) // the sort's values, where it sorts
      itemIndex[item] = static_cast<std::uint32_t>(item);

    WriteItemValues(k.referenceVolumes, k.volumeFraction, k.elasticity, k.rigidWeights, k.rigidInverseEdges,
                    k.rigidLimitVolumes, k.rigidStrainLimitSquared,
                    tetrahedra[item], source, target, itemOut + item * ItemValues);
  }
  __syncthreads();
  auto * out = reinterpret_cast<float4 *>(tasks + 2 * first);
  for (int q = local; q < count * 2 * TaskQuads; q += PrepareThreads)
    out[q] = stage.tasks[(q / (2 * TaskQuads)) * TaskStride + q % (2 * TaskQuads)];
}

/** Trilinear interpolation at texel position (x, y) and slice-pair
 *  coordinate s = z + 1/2 of an intensity texture of slice pairs (layer l:
 *  slices l - 1 and l, clamped; see UploadPacked): slice k's centre lies at
 *  z = k + 1/2, so the pair around z is layer floor(s), and s minus that is
 *  slice l's weight. Layers 0 and `top` pair the edge slice with itself, so
 *  outside them the weight does not matter and the layer is floor(min(s,
 *  top)) in one conversion that saturates (negatives to 0): with the
 *  compiler's own clamp to the instruction's 16-bit layer field, which it
 *  adds whatever the value, four instructions per fetch instead of six.
 *  One bilinear pass of 32-bit texels instead of a 3D texture's two passes,
 *  and the weight along z in single precision rather than the texture
 *  units' 8 fraction bits. On an H100, early generations' kernels sampled
 *  9.16e10 points per second against 9.01e10 with a 3D texture of 16-bit
 *  texels (cuda/early-h100-slice-pairs.txt); the texels read are as many
 *  bytes, so the texture units' data path still bounds it. */
__device__ __forceinline__ float
SlicePairTrilinear(cudaTextureObject_t pairs, float top, float x, float y, float s)
{
  unsigned short layer;
  asm("cvt.rmi.sat.u16.f32 %0, %1;" : "=h"(layer) : "f"(fminf(s, top)));
  // Level 0 named (TEX.LZ): no level-of-detail operand to set per fetch.
  const float2 v = tex2DLayeredLod<float2>(pairs, x, y, layer, 0.0f);
  return fmaf(s - floorf(s), v.y - v.x, v.x);
}

/** What the sampling kernel needs besides the tasks, by value. */
struct SamplingConstants
{
  cudaTextureObject_t movingIntensity, fixedIntensity;
  cudaTextureObject_t movingDistances[MaxTextureStructures], fixedDistances[MaxTextureStructures]; ///< slice pairs
  float               movingScales[MaxTextureStructures], fixedScales[MaxTextureStructures]; ///< mm per unit
  const std::uint8_t *movingNearBlocks, *fixedNearBlocks; ///< see PackedVolumeView::nearBlocks
  int                 movingBlocks[3], fixedBlocks[3];
  float               movingDepth, fixedDepth; ///< slices of each image (its top layer)
  float               guidanceWeights[MaxTextureStructures];
  float               radius, inverseRadius;
  std::uint32_t       chunkIterations; ///< 32 samples each
};

/** Items in the order an ItemSchedule gives, one thread per candidate: in
 *  place of the sort by tetrahedron (four memory sets and four kernels,
 *  about 35 us per part of a paper-scale batch on an H100). */
__global__ void
ScheduleCandidateItems(ItemSchedule schedule, std::uint32_t * sortedItems)
{
  const std::size_t c = schedule.firstCandidate + static_cast<std::size_t>(blockIdx.x) * blockDim.x + threadIdx.x;
  if (c >= schedule.endCandidate)
    return;
  const uint2         slot = reinterpret_cast<const uint2 *>(schedule.slots)[c]; // first place, stride
  const std::uint64_t first = schedule.candidateFirstItem[c];
  const auto          n = static_cast<std::uint32_t>(schedule.candidateFirstItem[c + 1] - first);
  const auto          item = static_cast<std::uint32_t>(first - schedule.partFirstItem);
  for (std::uint32_t j = 0; j < n; ++j)
    sortedItems[slot.x + j * slot.y] = item + j;
}

/** The task at schedule position `position`. */
__device__ std::uint32_t
ScheduledTask(const std::uint32_t * __restrict__ sortedItems, std::size_t position)
{
  return 2 * __ldg(sortedItems + position / 2) + static_cast<std::uint32_t>(position & 1);
}

__global__ void
GatherScheduleCounts(const std::uint32_t * __restrict__ sortedItems, const std::uint32_t * __restrict__ chunkCounts,
                     std::size_t tasks, std::uint32_t * scheduleCounts)
{
  const std::size_t position = static_cast<std::size_t>(blockIdx.x) * blockDim.x + threadIdx.x;
  if (position < tasks)
    scheduleCounts[position] = chunkCounts[ScheduledTask(sortedItems, position)];
}

/** Which task each chunk of the schedule belongs to, and where each task's
 *  chunks begin. */
__global__ void
ScatterChunkTasks(const std::uint32_t * __restrict__ sortedItems, const std::uint32_t * __restrict__ scheduleCounts,
                  const std::uint32_t * __restrict__ scheduleEnds, std::size_t tasks, std::size_t capacity,
                  std::uint32_t * taskFirstChunk, std::uint32_t * chunkTask)
{
  const std::size_t position = static_cast<std::size_t>(blockIdx.x) * blockDim.x + threadIdx.x;
  if (position >= tasks)
    return;
  const std::uint32_t task = ScheduledTask(sortedItems, position);
  const std::uint32_t end = scheduleEnds[position];
  const std::uint32_t first = end - scheduleCounts[position];
  taskFirstChunk[task] = first;
  for (std::uint32_t c = first; c < end && c < capacity; ++c)
    chunkTask[c] = task;
}

/** The mask's bits per block for a kernel instance reading `Slots`
 *  structures (the host's NearBlockBits for as many). */
template <int Slots>
constexpr int SlotMaskBits = NearBlockBits(Slots);

/** The structures whose distance at texel position `p` (along z the
 *  slice-pair coordinate, TexelCorners) may be below the guidance radius
 *  (PackedVolumeView::nearBlocks, MaskBits bits per block: bit g for
 *  structure g). The block of the footprint's first texel floor(p - 1/2),
 *  along z floor(s - 1), clamped as the texture clamps: the rule of
 *  morea_core::NearContourBlocks::BlockOf, in texel coordinates. */
template <int MaskBits>
__device__ unsigned
NearStructures(const std::uint8_t * __restrict__ nearBlocks, const int blocks[3], const float p[3])
{
  // 32-bit block numbers (an image has far fewer than 2^32 blocks): the
  // 64-bit index arithmetic was about 15 instructions per sample. With a
  // power-of-two block size, p / size - 1 / (2 size) is (p - 1/2) / size
  // exactly, in one multiply-add (along z s / size - 1 / size).
  static_assert((NearBlockSize & (NearBlockSize - 1)) == 0, "a power-of-two block size");
  // The conversion to unsigned takes negatives to 0: one clamp per axis.
  unsigned b[3];
#pragma unroll
  for (int a = 0; a < 3; ++a)
    b[a] = min(__float2uint_rd(fmaf(p[a], 1.0f / NearBlockSize, (a == 2 ? -1.0f : -0.5f) / NearBlockSize)),
               static_cast<unsigned>(blocks[a] - 1));
  const unsigned block = (b[2] * static_cast<unsigned>(blocks[1]) + b[1]) * static_cast<unsigned>(blocks[0]) + b[0];
  if constexpr (MaskBits == 4)
    return (__ldg(nearBlocks + (block >> 1)) >> (4 * (block & 1u))) & 0x0fu;
  else if constexpr (MaskBits == 8)
    return __ldg(nearBlocks + block);
  else
    return __ldg(reinterpret_cast<const std::uint16_t *>(nearBlocks) + block);
}

/** __log2f and __fdividef(1, x) without their guards for subnormal
 *  arguments (flush to zero): the same values for the normal arguments they
 *  get here (the logarithm's are at least 1/2; the sum is 0 or far above
 *  the subnormals), in one instruction instead of four (three for the
 *  reciprocal), about 15 of the 190 or so per sample. */
__device__ __forceinline__ float
Log2Approximate(float x)
{
  float y;
  asm("lg2.approx.ftz.f32 %0, %1;" : "=f"(y) : "f"(x));
  return y;
}

__device__ __forceinline__ float
ReciprocalApproximate(float x)
{
  float y;
  asm("rcp.approx.ftz.f32 %0, %1;" : "=f"(y) : "f"(x));
  return y;
}

/** Adds one sample's terms; `state`: its Sobol state (shift included). */
template <int Direction, int Slots>
__device__ __forceinline__ void
SamplePoint(const SamplingConstants & k, const float4 * corners, bool near, const std::uint32_t state[4],
            float & intensity, float & guidance)
{
  // The texture objects are kernel parameters chosen at compile time:
  // uniform, so each fetch is one instruction (chosen at run time, every
  // fetch was wrapped in a loop over the warp's distinct objects).
  const cudaTextureObject_t fromIntensity = Direction == 0 ? k.movingIntensity : k.fixedIntensity;
  const cudaTextureObject_t toIntensity = Direction == 0 ? k.fixedIntensity : k.movingIntensity;
  const std::uint8_t *      fromNearBlocks = Direction == 0 ? k.movingNearBlocks : k.fixedNearBlocks;
  const int *               fromBlocks = Direction == 0 ? k.movingBlocks : k.fixedBlocks;
  // The weights are w = -log2 u = 32 - l with u = (state + 1/2) / 2^32 and
  // l = log2(state + 1/2); their sum is 128 minus the sum of the l, and
  // w / sum = 32 / sum - l / sum: two instructions fewer than forming each
  // w first. (The sum loses a few more low bits of the l to cancellation,
  // about 1e-6 of a tetrahedron's size, far below the texture units' 1/256
  // of a texel.)
  float l[4];
#pragma unroll
  for (int d = 0; d < 4; ++d)
    l[d] = Log2Approximate(__uint2float_rn(state[d]) + 0.5f);
  const float inverseSum = ReciprocalApproximate(128.0f - ((l[0] + l[1]) + (l[2] + l[3])));
  const float scaled = 32.0f * inverseSum;
  const float b1 = fmaf(-l[1], inverseSum, scaled), b2 = fmaf(-l[2], inverseSum, scaled),
              b3 = fmaf(-l[3], inverseSum, scaled);
  // Corners from shared memory (broadcast loads): 51 registers instead
  // of 56 with them in registers, at the same speed on an H100.
  float p[3], r[3];
  {
    const float4 f0 = corners[0], f1 = corners[1], f2 = corners[2];
    p[0] = fmaf(b3, f2.y, fmaf(b2, f1.z, fmaf(b1, f0.w, f0.x)));
    p[1] = fmaf(b3, f2.z, fmaf(b2, f1.w, fmaf(b1, f1.x, f0.y)));
    p[2] = fmaf(b3, f2.w, fmaf(b2, f2.x, fmaf(b1, f1.y, f0.z)));
    const float4 t0 = corners[3], t1 = corners[4], t2 = corners[5];
    r[0] = fmaf(b3, t2.y, fmaf(b2, t1.z, fmaf(b1, t0.w, t0.x)));
    r[1] = fmaf(b3, t2.z, fmaf(b2, t1.w, fmaf(b1, t1.x, t0.y)));
    r[2] = fmaf(b3, t2.w, fmaf(b2, t2.x, fmaf(b1, t1.y, t0.z)));
  }
  const float a = SlicePairTrilinear(fromIntensity, Direction == 0 ? k.movingDepth : k.fixedDepth, p[0], p[1], p[2]);
  const float b = SlicePairTrilinear(toIntensity, Direction == 0 ? k.fixedDepth : k.movingDepth, r[0], r[1], r[2]);
  if (a > 0.0f && b > 0.0f)
  {
    const float d = a - b;
    intensity += d * d;
  }
  else if (a > 0.0f || b > 0.0f)
    intensity += 1.0f;
  // A structure's sampled distance only where the sample's block may be
  // within the radius of its contour (bits read mostly from L1 instead of
  // a filtered fetch), the mapped one only where the sampled one is: most
  // samples of a task near a contour are not, and few are near two.
  if (near)
  {
    // One test for the common case of no structure near the sample, not
    // one per structure.
    const unsigned structures = NearStructures<SlotMaskBits<Slots>>(fromNearBlocks, fromBlocks, p);
    if (structures != 0)
    {
      // Unrolled: each structure's textures stay uniform kernel parameters.
#pragma unroll
      for (int g = 0; g < Slots; ++g)
        if ((structures >> g) & 1u)
        {
          const float d =
            (Direction == 0 ? k.movingScales[g] : k.fixedScales[g]) *
            SlicePairTrilinear(Direction == 0 ? k.movingDistances[g] : k.fixedDistances[g],
                               Direction == 0 ? k.movingDepth : k.fixedDepth, p[0], p[1], p[2]);
          if (d < k.radius)
          {
            const float e = d - (Direction == 0 ? k.fixedScales[g] : k.movingScales[g]) *
                                  SlicePairTrilinear(Direction == 0 ? k.fixedDistances[g] : k.movingDistances[g],
                                                     Direction == 0 ? k.fixedDepth : k.movingDepth, r[0], r[1], r[2]);
            guidance += k.guidanceWeights[g] * (k.radius - d) * k.inverseRadius * e * e;
          }
        }
    }
  }
}

/** Samples rows j, j + 1, ... of a chunk (32 consecutive samples each) up
 *  to the chunk's end; `state`: the Sobol state of row j for this lane. */
template <int Direction, int Slots>
__device__ void
SampleRows(const SamplingConstants & k, const float4 * corners, std::uint32_t j, std::uint32_t n, bool near, int lane,
           std::uint32_t state[4], float & intensity, float & guidance)
{
  const std::uint32_t end = min(n, 32 * (j + k.chunkIterations));
  for (std::uint32_t row = 32 * j;;)
  {
    if (row + lane < end)
      SamplePoint<Direction, Slots>(k, corners, near, state, intensity, guidance);
    row += 32;
    if (row >= end)
      break;
    // Rows j and j + 1 differ in bits 0 and ctz(j + 1) + 1 of 2 j ^ j, the
    // row's part of the Gray code (see SobolWarpPart).
    const int high = __ffs(static_cast<int>(j + 1)) + 4; // ctz(j + 1) + 1 + 4
#pragma unroll
    for (int d = 0; d < 4; ++d)
      state[d] ^= c_SobolDirections[d * 32 + 4] ^ c_SobolDirections[d * 32 + high];
    ++j;
  }
}

/** Samples a whole chunk of 512 by cosets (morea/SampleCosets.h) of a block
 *  of 2^(MinCosetBits + level); `state`: the Sobol state of the chunk's
 *  first coset for this lane. */
template <int Direction, int Slots>
__device__ void
SampleCosetRows(const SamplingConstants & k, const float4 * corners, bool near, int level, std::uint32_t state[4],
                float & intensity, float & guidance)
{
  for (std::uint32_t row = 0;;)
  {
    SamplePoint<Direction, Slots>(k, corners, near, state, intensity, guidance);
    if (++row == CosetRows)
      break;
    const uint4 step = c_CosetRowSteps[level][__ffs(static_cast<int>(row)) - 1];
    state[0] ^= step.x;
    state[1] ^= step.y;
    state[2] ^= step.z;
    state[3] ^= step.w;
  }
}

/** What a warp needs of its chunk before the first fetch: three dependent
 *  loads (the chunk's task, where the task's chunks begin, the task). */
struct ChunkHeader
{
  uint4         shift;
  std::uint32_t task;
  std::uint32_t local; ///< the chunk's place among its task's chunks
  std::uint32_t n;     ///< the task's samples
  bool          near;
};

/** Starts the loads of a chunk's header; lanes `cornerLane` .. + 5 put the
 *  task's corners into `corners`. */
__device__ __forceinline__ ChunkHeader
LoadChunk(const SampleTask * __restrict__ tasks, const std::uint32_t * __restrict__ taskFirstChunk,
          const std::uint32_t * __restrict__ chunkTask, std::size_t chunk, int lane, int cornerLane, float4 * corners)
{
  ChunkHeader h;
  h.task = __ldg(chunkTask + chunk);
  h.local = static_cast<std::uint32_t>(chunk) - __ldg(taskFirstChunk + h.task);
  // All lanes read the same task: one transaction per 16-byte load.
  const float4 * q = reinterpret_cast<const float4 *>(tasks + h.task);
  if (lane >= cornerLane && lane < cornerLane + 6)
    corners[lane - cornerLane] = __ldg(q + (lane - cornerLane));
  h.shift = __ldg(reinterpret_cast<const uint4 *>(q + 6));
  h.n = __ldg(reinterpret_cast<const std::uint32_t *>(q + 7));
  h.near = __ldg(reinterpret_cast<const std::uint32_t *>(q + 7) + 1) != 0;
  return h;
}

/** One warp samples one chunk whose header is loaded and writes its two sums.
 *
 *  The kernel waits mostly on its texture fetches and issues an instruction
 *  in about half of the cycles, so the per-sample arithmetic is kept short:
 *  the Sobol state goes from one row to the next by two XORs per dimension
 *  (Gray-code order), the barycentric weights use base-2 logarithms (the
 *  -ln 2 factor cancels in the normalisation) and an approximate reciprocal,
 *  a point is corner 0 plus three multiply-adds per axis, and the texture
 *  objects are uniform (SampleRows). On an H100, with the paper's
 *  configuration: 0.279 -> 0.248 s of kernels per generation.
 *  Tried and not kept (same machine, kernels per generation):
 *  - 5 or 6 resident blocks per SM (46 or 40 registers, no spills): 0.254 and
 *    0.255 s against 0.248 s with 4;
 *  - sorting a chunk's points by the ordering of their barycentric weights
 *    before fetching them (each warp instruction then covers a compact part
 *    of the tetrahedron; L1 hit rate 81 -> 84 %): 0.35 s against 0.28 s, the
 *    sort's instructions cost more than the fetches saved;
 *  - two samples per lane in flight: 0.286-0.290 s against 0.265 s;
 *  - the mapped image read through the load path instead (per voxel its
 *    2 x 2 x 2 texels as one 16-byte brick, software trilinear), since the
 *    texture units' data pipe is the limit (81 % busy, the load path 27 %):
 *    8.09e10 samples per second when tasks of at most 1024 samples used it,
 *    7.06e10 when all did, against 8.33e10; the bricks' eightfold footprint
 *    costs more in L1 than the second pipe gains;
 *  - lanes taking samples that differ in the high bits of an aligned block's
 *    Gray codes (the same points): 8.32e10 against 8.33e10. Flipping a high
 *    index bit moves Sobol dimensions 2-4 by a direction number with
 *    arbitrary high bits, so those points are no closer together. A
 *    diagnostic build whose 32 lanes differed only in dimension 1 (wrong
 *    values) reached 1.13e11: close points pay. Offsets chosen from the
 *    whole block, not single bits, find them (morea/SampleCosets.h). */
template <int Slots>
__device__ void
SampleChunk(const SamplingConstants & k, const ChunkHeader & h, std::size_t chunk, int lane, const float4 * corners,
            double2 * chunkSums, double * directionOut)
{
  const int           direction = static_cast<int>(h.task & 1u);
  std::uint32_t       j = h.local * k.chunkIterations;
  const bool          cosets = k.chunkIterations == CosetRows && 32 * (j + CosetRows) <= h.n; // uniform
  int                 level = 0;
  uint4               lanePart;
  std::uint32_t       state[4] = { h.shift.x, h.shift.y, h.shift.z, h.shift.w };
  if (cosets)
  {
    // The block's first index, the chunk's first coset in it (Gray-code
    // order over the complement), the lane's element of W.
    const CosetBlock block = WholeChunkBlock(h.n / CosetChunkSamples, h.local);
    level = block.bits - MinCosetBits;
    j = block.firstChunk * CosetRows;
    const std::uint32_t coset = CosetRows * (h.local - block.firstChunk);
    for (std::uint32_t gray = coset ^ (coset >> 1), b = 0; gray; gray >>= 1, ++b) // warp-uniform loop
      if (gray & 1u)
      {
        const uint4 step = c_CosetRowSteps[level][b];
        state[0] ^= step.x;
        state[1] ^= step.y;
        state[2] ^= step.z;
        state[3] ^= step.w;
      }
    lanePart = g_CosetLaneSobol[level][lane];
  }
  else
    lanePart = g_LaneSobol[lane];
  state[0] ^= lanePart.x;
  state[1] ^= lanePart.y;
  state[2] ^= lanePart.z;
  state[3] ^= lanePart.w;
  {
    std::uint32_t rowPart[4];
    SobolWarpPart(j, c_SobolDirections, rowPart);
#pragma unroll
    for (int d = 0; d < 4; ++d)
      state[d] ^= rowPart[d];
  }

  float intensity = 0.0f, guidance = 0.0f;
  if (cosets) // both conditions are the same for the whole warp
  {
    if (direction == 0)
      SampleCosetRows<0, Slots>(k, corners, h.near, level, state, intensity, guidance);
    else
      SampleCosetRows<1, Slots>(k, corners, h.near, level, state, intensity, guidance);
  }
  else if (direction == 0)
    SampleRows<0, Slots>(k, corners, j, h.n, h.near, lane, state, intensity, guidance);
  else
    SampleRows<1, Slots>(k, corners, j, h.n, h.near, lane, state, intensity, guidance);
  const double intensitySum = WarpSum(static_cast<double>(intensity));
  const double guidanceSum = WarpSum(static_cast<double>(guidance));
  if (lane != 0)
    return;
  // A task's only chunk holds its values (0 + x is x): SumChunks then
  // passes over most tasks without reading their chunk sums and counts.
  if (directionOut != nullptr && h.n <= 32 * k.chunkIterations)
  {
    double * out = directionOut + static_cast<std::size_t>(h.task) * DirectionValues;
    out[0] = intensitySum;
    out[1] = guidanceSum;
    out[2] = static_cast<double>(h.n);
  }
  else
    chunkSums[chunk] = make_double2(intensitySum, guidanceSum);
}

/** Two chunks per warp, in schedule order: consecutive warps take the same
 *  tetrahedron of several solutions (see PrepareWorkspace). The second
 *  chunk's header loads while the first is sampled: on an H100, 9.09e10
 *  samples per second against 9.02e10 with one chunk per warp, the same
 *  sums. */
template <int Slots>
__global__ void __launch_bounds__(SampleWarpsPerBlock * 32, SampleBlocksPerMultiprocessor)
SampleTextureChunks(SamplingConstants k, const SampleTask * __restrict__ tasks,
                    const std::uint32_t * __restrict__ taskFirstChunk, const std::uint32_t * __restrict__ chunkTask,
                    const std::uint32_t * __restrict__ totalChunks, std::size_t capacity, double2 * chunkSums,
                    double * directionOut)
{
  __shared__ float4 corners[SampleWarpsPerBlock][2][6];
  const int         warp = static_cast<int>(threadIdx.x / 32), lane = static_cast<int>(threadIdx.x & 31);
  // The grid is sized for the capacity: warps past the chunks found leave.
  const std::size_t chunks = min(static_cast<std::size_t>(__ldg(totalChunks)), capacity);
  const std::size_t first = 2 * ((static_cast<std::size_t>(blockIdx.x) * blockDim.x + threadIdx.x) / 32);
  if (first >= chunks) // whole warps leave together
    return;
  const bool        second = first + 1 < chunks;
  const ChunkHeader a = LoadChunk(tasks, taskFirstChunk, chunkTask, first, lane, 0, corners[warp][0]);
  ChunkHeader       b{};
  if (second)
    b = LoadChunk(tasks, taskFirstChunk, chunkTask, first + 1, lane, 8, corners[warp][1]);
  __syncwarp();
  if constexpr (Slots <= 4)
  {
    SampleChunk<Slots>(k, a, first, lane, corners[warp][0], chunkSums, directionOut);
    if (second)
      SampleChunk<Slots>(k, b, first + 1, lane, corners[warp][1], chunkSums, directionOut);
  }
  else
  {
    // One copy of the sampling code for both chunks: inlined twice, the
    // instance of 16 slots took 99 KB of instructions (52 KB so), that of
    // 8 slots 61 KB (34 KB). On an H200, 20 early generations of the
    // paper's configuration with its two structures given 6 times each
    // took 3.16 s in kernels against 3.74 s, given 3 times each 2.02 s
    // against 2.05 s; the same values.
    ChunkHeader h = a;
#pragma unroll 1
    for (int c = 0;;)
    {
      SampleChunk<Slots>(k, h, first + c, lane, corners[warp][c], chunkSums, directionOut);
      if (++c == (second ? 2 : 1))
        break;
      h = b;
    }
  }
}

/** One warp per listed chunk (item, direction, the chunk's place among its
 *  task's chunks) of items whose corners `corners` holds: the task is set
 *  up in the warp as step 1 sets it up, and the chunk sampled as in
 *  SampleTextureChunks, so its sums are those the schedule gives it. For a
 *  few candidates' items at a time, without step 1's sort and scan. */
template <int Slots>
__global__ void __launch_bounds__(SampleWarpsPerBlock * 32)
SampleListedChunks(SamplingConstants s, EvaluationConstants k, const double * __restrict__ corners,
                   const uint4 * __restrict__ list, std::size_t entries, double2 * chunkSums)
{
  __shared__ SampleTask tasks[SampleWarpsPerBlock];
  __shared__ float4     taskCorners[SampleWarpsPerBlock][6];
  const int             warp = static_cast<int>(threadIdx.x / 32), lane = static_cast<int>(threadIdx.x & 31);
  const std::size_t     entry = (static_cast<std::size_t>(blockIdx.x) * blockDim.x + threadIdx.x) / 32;
  if (entry >= entries) // whole warps leave together
    return;
  const uint4 e = list[entry];
  if (lane == 0)
  {
    double         source[12], target[12];
    const double * c = corners + static_cast<std::size_t>(e.x) * ItemCorners;
    for (int i = 0; i < 12; ++i)
    {
      source[i] = c[i];
      target[i] = c[12 + i];
    }
    if (e.y == 0)
      PrepareDirection(k, source, target, k.packedMoving, k.packedFixed, tasks[warp]);
    else
      PrepareDirection(k, target, source, k.packedFixed, k.packedMoving, tasks[warp]);
  }
  __syncwarp();
  const SampleTask & task = tasks[warp];
  if (lane < 6)
    taskCorners[warp][lane] = reinterpret_cast<const float4 *>(&task)[lane];
  ChunkHeader h;
  h.task = e.y;
  h.local = e.z;
  h.n = task.samples;
  h.near = task.nearContour != 0;
  h.shift = make_uint4(task.shift[0], task.shift[1], task.shift[2], task.shift[3]);
  __syncwarp();
  SampleChunk<Slots>(s, h, entry, lane, taskCorners[warp], chunkSums, nullptr);
}

/** Each direction's chunk sums in chunk order: the result does not depend on
 *  how the warps were scheduled. Tasks of one chunk have their values from
 *  the sampling kernel already (SampleChunk). */
__global__ void
SumChunks(const SampleTask * __restrict__ tasks, const std::uint32_t * __restrict__ chunkCounts,
          const std::uint32_t * __restrict__ taskFirstChunk, const double2 * __restrict__ chunkSums,
          std::size_t tasksCount, std::size_t capacity, double * directionOut)
{
  const std::size_t task = static_cast<std::size_t>(blockIdx.x) * blockDim.x + threadIdx.x;
  if (task >= tasksCount || chunkCounts[task] == 1)
    return;
  const std::uint32_t first = taskFirstChunk[task];
  double              intensity = 0.0, guidance = 0.0;
  // Past the capacity the sums are wrong anyway (the caller samples again).
  for (std::uint32_t c = first; c < first + chunkCounts[task] && c < capacity; ++c)
  {
    const double2 s = chunkSums[c];
    intensity += s.x;
    guidance += s.y;
  }
  double * out = directionOut + task * DirectionValues;
  out[0] = intensity;
  out[1] = guidance;
  out[2] = static_cast<double>(tasks[task].samples);
}
/** Calls launch(std::integral_constant<int, Slots>) with the sampling
 *  kernels' instance for the images' structures: it reads at most Slots
 *  structures per sample, 3, 4, 8 or 16 (MaxTextureStructures), the fewest
 *  that hold them. A slot costs an unrolled test of its bit per sample near
 *  a contour, registers (48 at most) and instructions: up to 3 structures
 *  run the kernel of before, instruction for instruction (an instance of 2
 *  slots spilled 8 bytes; that of 16 spills 4, outside the sampling
 *  loops). On an H200, 20 early generations of the paper's configuration
 *  took 1.56 s in kernels with its 2 structures, 2.02 s with them given 3
 *  times each (8 slots) and 3.16 s given 6 times each (16 slots): every
 *  copy is read near the same contours. */
template <typename Launch>
void
WithStructureSlots(const EvaluationConstants & constants, Launch && launch)
{
  static_assert(MaxTextureStructures == 16, "the largest instance reads MaxTextureStructures");
  const int structures = std::max(constants.packedMoving.distanceMaps, constants.packedFixed.distanceMaps);
  if (structures <= 3)
    launch(std::integral_constant<int, 3>{});
  else if (structures <= 4)
    launch(std::integral_constant<int, 4>{});
  else if (structures <= 8)
    launch(std::integral_constant<int, 8>{});
  else
    launch(std::integral_constant<int, 16>{});
}

SamplingConstants
SamplingConstantsOf(const EvaluationConstants & constants)
{
  SamplingConstants k;
  k.movingIntensity = static_cast<cudaTextureObject_t>(constants.packedMoving.intensityTexture);
  k.fixedIntensity = static_cast<cudaTextureObject_t>(constants.packedFixed.intensityTexture);
  for (int g = 0; g < MaxTextureStructures; ++g)
  {
    k.movingDistances[g] = static_cast<cudaTextureObject_t>(constants.packedMoving.distancePairTextures[g]);
    k.fixedDistances[g] = static_cast<cudaTextureObject_t>(constants.packedFixed.distancePairTextures[g]);
    k.movingScales[g] = constants.packedMoving.distanceScales[g];
    k.fixedScales[g] = constants.packedFixed.distanceScales[g];
  }
  k.movingNearBlocks = constants.packedMoving.nearBlocks;
  k.fixedNearBlocks = constants.packedFixed.nearBlocks;
  for (int a = 0; a < 3; ++a)
  {
    k.movingBlocks[a] = constants.packedMoving.blocks[a];
    k.fixedBlocks[a] = constants.packedFixed.blocks[a];
  }
  k.movingDepth = static_cast<float>(constants.packedMoving.size[2]);
  k.fixedDepth = static_cast<float>(constants.packedFixed.size[2]);
  for (int g = 0; g < MaxTextureStructures; ++g)
    k.guidanceWeights[g] = constants.textureGuidanceWeights[g];
  k.radius = static_cast<float>(constants.guidanceRadius);
  k.inverseRadius = static_cast<float>(1.0 / constants.guidanceRadius);
  k.chunkIterations = constants.chunkSamples / 32;
  return k;
}
} // namespace

void
UploadTextureSobolDirections(const std::uint32_t * directions)
{
  Check(cudaMemcpyToSymbol(c_SobolDirections, directions, sizeof(std::uint32_t) * 4 * 32),
        "copying the Sobol direction numbers");
  // The state part of an index offset x within a block (SobolStateOfOffset).
  const auto part = [directions](std::uint32_t x) {
    const std::array<std::uint32_t, 4> p = SobolStateOfOffset(x, directions);
    return make_uint4(p[0], p[1], p[2], p[3]);
  };
  uint4 lanes[32];
  for (std::uint32_t lane = 0; lane < 32; ++lane)
    lanes[lane] = part(lane);
  Check(cudaMemcpyToSymbol(g_LaneSobol, lanes, sizeof(lanes)), "copying the lanes' Sobol parts");

  const SampleCosetLayout & layout = SampleCosets();
  uint4                     cosetLanes[CosetLevels][32], rowSteps[CosetLevels][MaxCosetRowBits] = {};
  for (int level = 0; level < CosetLevels; ++level)
  {
    for (int lane = 0; lane < 32; ++lane)
      cosetLanes[level][lane] = part(layout.laneOffsets[level][lane]);
    for (int b = 0; b < MinCosetBits + level - 5; ++b)
      rowSteps[level][b] = part(layout.rowOffsets[level][b]);
  }
  Check(cudaMemcpyToSymbol(g_CosetLaneSobol, cosetLanes, sizeof(cosetLanes)), "copying the lanes' coset parts");
  Check(cudaMemcpyToSymbol(c_CosetRowSteps, rowSteps, sizeof(rowSteps)), "copying the cosets' row steps");
}

std::size_t
TexturePrepareWorkspaceBytes(std::size_t items)
{
  return WorkspaceBytes(items);
}

std::size_t
TextureChunkWorkspaceBytes(std::size_t chunks)
{
  return Aligned(chunks * sizeof(double2)) + Aligned(chunks * sizeof(std::uint32_t));
}

void
LaunchPrepareTexture(const EvaluationConstants & constants, const double * corners, const std::uint32_t * tetrahedra,
                     const std::uint8_t * itemSkip, std::size_t items, const ItemSchedule & schedule,
                     void * workspace, double * itemOut, void * stream)
{
  if (items == 0)
    return;
  if (2 * items > 0x7fffffffu)
    throw Error("CUDA backend: too many tetrahedra in one batch");
  const cudaStream_t     s = static_cast<cudaStream_t>(stream);
  const PrepareWorkspace w = Partition(workspace, items);
  const unsigned         blocks = static_cast<unsigned>((items + PrepareThreads - 1) / PrepareThreads);
  const bool sorted = schedule.slots == nullptr;
  PrepareTextureTasks<<<blocks, PrepareThreads, 0, s>>>(constants, corners, tetrahedra, itemSkip, items, w.tasks,
                                                        w.chunkCounts, sorted ? w.itemIndex : nullptr, itemOut);
  Check(cudaGetLastError(), "launching the texture set-up kernel");
  if (sorted)
  {
    // Only the bits a tetrahedron index can have: 2 passes instead of 4
    // for a few thousand tetrahedra (ScratchBytes sized the sort for 32).
    int keyBits = constants.tetrahedra == 0 ? 32 : 1; // 0: not known
    while (keyBits < 32 && (std::uint64_t{ 1 } << keyBits) < constants.tetrahedra)
      ++keyBits;
    std::size_t bytes = w.scratchBytes;
    Check(cub::DeviceRadixSort::SortPairs(w.scratch, bytes, tetrahedra, w.sortedKeys, w.itemIndex, w.sortedItems,
                                          static_cast<int>(items), 0, keyBits, s),
          "sorting the schedule by tetrahedron");
  }
  else
  {
    const std::size_t candidates = schedule.endCandidate - schedule.firstCandidate;
    ScheduleCandidateItems<<<static_cast<unsigned>((candidates + 127) / 128), 128, 0, s>>>(schedule, w.sortedItems);
    Check(cudaGetLastError(), "launching the schedule of candidates' items");
  }
  const std::size_t tasks = 2 * items;
  const unsigned    taskBlocks = static_cast<unsigned>((tasks + 255) / 256);
  GatherScheduleCounts<<<taskBlocks, 256, 0, s>>>(w.sortedItems, w.chunkCounts, tasks, w.scheduleCounts);
  Check(cudaGetLastError(), "launching the schedule kernel");
  std::size_t bytes = w.scratchBytes;
  Check(cub::DeviceScan::InclusiveSum(w.scratch, bytes, w.scheduleCounts, w.scheduleEnds, static_cast<int>(tasks), s),
        "scanning the chunk counts");
}

void
CopyTextureChunkCount(std::size_t items, const void * workspace, std::uint32_t * totalChunks, void * stream)
{
  if (items == 0)
    return;
  const PrepareWorkspace w = Partition(const_cast<void *>(workspace), items);
  Check(cudaMemcpyAsync(totalChunks, w.scheduleEnds + 2 * items - 1, sizeof(std::uint32_t), cudaMemcpyDeviceToHost,
                        static_cast<cudaStream_t>(stream)),
        "copying the number of chunks");
}

void
LaunchSampleTexture(const EvaluationConstants & constants, std::size_t items, void * workspace,
                    std::size_t chunkCapacity, void * chunkWorkspace, double * directionOut, void * stream)
{
  if (items == 0)
    return;
  const cudaStream_t     s = static_cast<cudaStream_t>(stream);
  const PrepareWorkspace w = Partition(workspace, items);
  auto *                 chunkSums = static_cast<double2 *>(chunkWorkspace);
  auto * chunkTask = reinterpret_cast<std::uint32_t *>(static_cast<unsigned char *>(chunkWorkspace) +
                                                       Aligned(chunkCapacity * sizeof(double2)));
  const std::size_t tasks = 2 * items;
  const unsigned    taskBlocks = static_cast<unsigned>((tasks + 255) / 256);
  ScatterChunkTasks<<<taskBlocks, 256, 0, s>>>(w.sortedItems, w.scheduleCounts, w.scheduleEnds, tasks, chunkCapacity,
                                               w.taskFirstChunk, chunkTask);
  Check(cudaGetLastError(), "launching the chunk scatter kernel");

  const SamplingConstants k = SamplingConstantsOf(constants);
  if (chunkCapacity > 0)
  {
    const std::size_t warps = (chunkCapacity + 1) / 2;
    const unsigned    sampleBlocks = static_cast<unsigned>((warps + SampleWarpsPerBlock - 1) / SampleWarpsPerBlock);
    WithStructureSlots(constants, [&](auto slots) {
      SampleTextureChunks<decltype(slots)::value><<<sampleBlocks, SampleWarpsPerBlock * 32, 0, s>>>(
        k, w.tasks, w.taskFirstChunk, chunkTask, w.scheduleEnds + tasks - 1, chunkCapacity, chunkSums, directionOut);
    });
    Check(cudaGetLastError(), "launching the texture sampling kernel");
  }
  SumChunks<<<taskBlocks, 256, 0, s>>>(w.tasks, w.chunkCounts, w.taskFirstChunk, chunkSums, tasks, chunkCapacity,
                                       directionOut);
  Check(cudaGetLastError(), "launching the chunk sum kernel");
}
void
LaunchSampleListedChunks(const EvaluationConstants & constants, const double * corners, const std::uint32_t * list,
                         std::size_t entries, double * chunkSums, void * stream)
{
  if (entries == 0)
    return;
  const unsigned blocks = static_cast<unsigned>((entries + SampleWarpsPerBlock - 1) / SampleWarpsPerBlock);
  WithStructureSlots(constants, [&](auto slots) {
    SampleListedChunks<decltype(slots)::value><<<blocks, SampleWarpsPerBlock * 32, 0, static_cast<cudaStream_t>(stream)>>>(
      SamplingConstantsOf(constants), constants, corners, reinterpret_cast<const uint4 *>(list), entries,
      reinterpret_cast<double2 *>(chunkSums));
  });
  Check(cudaGetLastError(), "launching the listed chunks' sampling");
}
} // namespace morea_core::cuda

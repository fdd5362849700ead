// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
// Filtered fetches per second of the texel formats the sampling kernel could
// use, as a warp's 32 lanes spread over cubes of growing edge: how much a
// format and the lanes' spread cost on this GPU, apart from the rest of the
// kernel. Needs the CUDA runtime and the project's headers only; built where
// it runs, from the repository root:
//   nvcc -O3 -std=c++17 -arch=sm_90 -I include -I src/cuda -o texture-footprints \
//     tools/profiling/texture-footprints.cu && ./texture-footprints
// Formats: a 3D float texture (the fetch-rate yardstick's), a 3D 16-bit
// normalised one (the intensity texels), and 2D layers of 16-bit pairs
// (slices l - 1 and l in one 32-bit texel, trilinear from one bilinear
// fetch and a lerp along z), and a 3D texture of float2 (two distance maps).
#include "DeviceMemory.h"

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <vector>

namespace
{
using morea_core::cuda::Check;
using morea_core::cuda::Texture3D;
using morea_core::cuda::TextureLayout;

constexpr int Edge = 256;
constexpr int Fetches = 64;

__device__ std::uint32_t
Hash(std::uint32_t x)
{
  x ^= x >> 16;
  x *= 0x7feb352du;
  x ^= x >> 15;
  x *= 0x846ca68bu;
  x ^= x >> 16;
  return x;
}

__device__ float
Unit(std::uint32_t h)
{
  return static_cast<float>(h >> 8) * (1.0f / 16777216.0f);
}

enum Format
{
  Float3D,
  Ushort3D,
  PairLayers,
  Float2x3D,
  QuadRows,
  Bricks
};

/** Each warp's fetch i lies in a cube of edge `spread` texels placed at
 *  random; its lanes at random places in the cube. */
template <int F>
__global__ void
Fetch(cudaTextureObject_t t, float spread, float * out)
{
  const std::uint32_t thread = blockIdx.x * blockDim.x + threadIdx.x;
  const std::uint32_t warp = thread / 32;
  float               sum = 0.0f;
  for (int i = 0; i < Fetches; ++i)
  {
    const std::uint32_t w = Hash(warp * 977u + i * 7919u), l = Hash(thread * 131u + i * 104729u);
    const float         room = Edge - 2.0f - spread;
    const float x = 1.0f + Unit(w) * room + Unit(l) * spread;
    const float y = 1.0f + Unit(Hash(w + 1)) * room + Unit(Hash(l + 1)) * spread;
    const float z = 1.0f + Unit(Hash(w + 2)) * room + Unit(Hash(l + 2)) * spread;
    if (F == Float3D || F == Ushort3D)
      sum += tex3D<float>(t, x, y, z);
    else if (F == Float2x3D)
    {
      const float2 v = tex3D<float2>(t, x, y, z);
      sum += v.x + v.y;
    }
    else if (F == QuadRows)
    {
      // Row pair floor(y + 1/2) read at its texel centre: no weight on the
      // next row, so the filter works along x only.
      const float  s = z + 0.5f, layer = floorf(s), r = y + 0.5f, row = floorf(r);
      const float4 v = tex2DLayered<float4>(t, x, row + 0.5f, min(max(static_cast<int>(layer), 0), Edge));
      const float  fy = r - row, lo = fmaf(fy, v.y - v.x, v.x), hi = fmaf(fy, v.w - v.z, v.z);
      sum += fmaf(s - layer, hi - lo, lo);
    }
    else if (F == Bricks)
    {
      // One unfiltered 16-byte texel: the 2 x 2 x 2 voxels around the point
      // as 16-bit values; trilinear in software.
      const float  sx = x + 0.5f, sy = y + 0.5f, sz = z + 0.5f;
      const float  ix = floorf(sx), iy = floorf(sy), iz = floorf(sz);
      const uint4  b = tex3D<uint4>(t, ix + 0.5f, iy + 0.5f, iz + 0.5f);
      const float  fx = sx - ix, fy = sy - iy, fz = sz - iz;
      const auto   lo16 = [](std::uint32_t w) { return static_cast<float>(w & 0xffffu); };
      const auto   hi16 = [](std::uint32_t w) { return static_cast<float>(w >> 16); };
      const float  x00 = fmaf(fx, hi16(b.x) - lo16(b.x), lo16(b.x)), x10 = fmaf(fx, hi16(b.y) - lo16(b.y), lo16(b.y));
      const float  x01 = fmaf(fx, hi16(b.z) - lo16(b.z), lo16(b.z)), x11 = fmaf(fx, hi16(b.w) - lo16(b.w), lo16(b.w));
      const float  y0 = fmaf(fy, x10 - x00, x00), y1 = fmaf(fy, x11 - x01, x01);
      sum += fmaf(fz, y1 - y0, y0) * (1.0f / 65535.0f);
    }
    else
    {
      const float  s = z + 0.5f, layer = floorf(s);
      const float2 v = tex2DLayered<float2>(t, x, y, min(max(static_cast<int>(layer), 0), Edge));
      sum += fmaf(s - layer, v.y - v.x, v.x);
    }
  }
  out[thread] = sum;
}

template <int F>
double
Rate(cudaTextureObject_t t, float spread, float * out, int threads)
{
  cudaEvent_t a, b;
  cudaEventCreate(&a);
  cudaEventCreate(&b);
  std::vector<float> ms;
  for (int r = 0; r < 7; ++r)
  {
    cudaEventRecord(a);
    Fetch<F><<<threads / 256, 256>>>(t, spread, out);
    Check(cudaGetLastError(), "launch");
    cudaEventRecord(b);
    Check(cudaEventSynchronize(b), "run");
    float m = 0;
    cudaEventElapsedTime(&m, a, b);
    if (r >= 2)
      ms.push_back(m);
  }
  std::sort(ms.begin(), ms.end());
  return static_cast<double>(threads) * Fetches / (1e-3 * ms[ms.size() / 2]);
}
} // namespace

int
main()
{
  const std::size_t          voxels = static_cast<std::size_t>(Edge) * Edge * Edge;
  std::vector<float>         f(voxels);
  std::vector<std::uint16_t> u(voxels), pairs(2 * voxels + 2 * Edge * Edge);
  std::vector<float>         f2(2 * voxels);
  for (std::size_t i = 0; i < voxels; ++i)
  {
    f[i] = static_cast<float>((i * 2654435761u) % 1000u) * 1e-3f;
    u[i] = static_cast<std::uint16_t>(f[i] * 65535.0f);
    f2[2 * i] = f[i];
    f2[2 * i + 1] = 1.0f - f[i];
  }
  const std::size_t slice = static_cast<std::size_t>(Edge) * Edge;
  for (int l = 0; l <= Edge; ++l)
    for (std::size_t v = 0; v < slice; ++v)
    {
      pairs[2 * (l * slice + v)] = u[std::max(l - 1, 0) * slice + v];
      pairs[2 * (l * slice + v) + 1] = u[std::min(l, Edge - 1) * slice + v];
    }
  const int       volume[3] = { Edge, Edge, Edge }, layers[3] = { Edge, Edge, Edge + 1 };
  const Texture3D tf(f.data(), 4, cudaCreateChannelDesc<float>(), volume);
  const Texture3D tu(u.data(), 2, cudaCreateChannelDesc<unsigned short>(), volume);
  const Texture3D tp(pairs.data(), 4, cudaCreateChannelDesc<ushort2>(), layers, TextureLayout::Layers);
  const Texture3D t2(f2.data(), 8, cudaCreateChannelDesc<float2>(), volume);
  // Row pairs of slice pairs (rows j - 1, j of slices l - 1, l), and
  // 2 x 2 x 2 bricks around each texel corner (voxels i - 1, i per axis).
  const auto clampAt = [](int i) { return std::min(std::max(i, 0), Edge - 1); };
  std::vector<std::uint16_t> quads(4 * static_cast<std::size_t>(Edge) * (Edge + 1) * (Edge + 1));
  for (int l = 0; l <= Edge; ++l)
    for (int j = 0; j <= Edge; ++j)
      for (int i = 0; i < Edge; ++i)
      {
        std::uint16_t * q = quads.data() + 4 * ((static_cast<std::size_t>(l) * (Edge + 1) + j) * Edge + i);
        const auto      at = [&](int jj, int ll) { return u[(static_cast<std::size_t>(clampAt(ll)) * Edge + clampAt(jj)) * Edge + i]; };
        q[0] = at(j - 1, l - 1);
        q[1] = at(j, l - 1);
        q[2] = at(j - 1, l);
        q[3] = at(j, l);
      }
  const int       quadLayers[3] = { Edge, Edge + 1, Edge + 1 };
  const Texture3D tq(quads.data(), 8, cudaCreateChannelDesc<ushort4>(), quadLayers, TextureLayout::Layers);
  const int                  brickEdge = Edge + 1;
  std::vector<std::uint32_t> bricks(4 * static_cast<std::size_t>(brickEdge) * brickEdge * brickEdge);
  for (int k = 0; k < brickEdge; ++k)
    for (int j = 0; j < brickEdge; ++j)
      for (int i = 0; i < brickEdge; ++i)
      {
        std::uint32_t * b = bricks.data() + 4 * ((static_cast<std::size_t>(k) * brickEdge + j) * brickEdge + i);
        const auto      at = [&](int ii, int jj, int kk) {
          return static_cast<std::uint32_t>(
            u[(static_cast<std::size_t>(clampAt(kk)) * Edge + clampAt(jj)) * Edge + clampAt(ii)]);
        };
        for (int c = 0; c < 4; ++c) // c: (y, z) corner; x pair in one word
          b[c] = at(i - 1, j - 1 + (c & 1), k - 1 + (c >> 1)) | at(i, j - 1 + (c & 1), k - 1 + (c >> 1)) << 16;
      }
  const int       brickSize[3] = { brickEdge, brickEdge, brickEdge };
  const Texture3D tb(bricks.data(), 16, cudaCreateChannelDesc<uint4>(), brickSize, TextureLayout::Volume,
                     morea_core::cuda::TextureFilter::Point);
  const int                 threads = 132 * 2048 * 4;
  morea_core::cuda::DeviceArray<float> buffer(threads);
  float *                         out = buffer.Data();
  cudaDeviceProp p{};
  cudaGetDeviceProperties(&p, 0);
  std::printf("%s; filtered fetches per second (1e9) by the edge of the cube a warp's lanes spread over\n", p.name);
  std::printf("%8s %12s %12s %12s %12s %12s %12s\n", "edge", "float 3D", "ushort 3D", "pair layers", "float2 3D",
              "quad rows", "bricks");
  for (float spread : { 0.0f, 1.0f, 2.0f, 3.0f, 4.0f, 6.0f, 8.0f, 12.0f, 16.0f, 32.0f })
    std::printf("%8.0f %12.1f %12.1f %12.1f %12.1f %12.1f %12.1f\n", spread,
                1e-9 * Rate<Float3D>(tf.Get(), spread, out, threads),
                1e-9 * Rate<Ushort3D>(tu.Get(), spread, out, threads),
                1e-9 * Rate<PairLayers>(tp.Get(), spread, out, threads),
                1e-9 * Rate<Float2x3D>(t2.Get(), spread, out, threads),
                1e-9 * Rate<QuadRows>(tq.Get(), spread, out, threads),
                1e-9 * Rate<Bricks>(tb.Get(), spread, out, threads));
  return 0;
}

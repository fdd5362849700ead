// Filtered fetches per second of the texel formats the sampling kernel could
// use, as a warp's 32 lanes spread over cubes of growing edge: how much a
// format and the lanes' spread cost on this GPU, apart from the rest of the
// kernel. Needs the CUDA runtime and the project's headers only; built where
// it runs, from the repository root:
//   nvcc -O3 -std=c++17 -arch=sm_90 -I include -I src/cuda -o texture-footprints \
//     bench/tools/texture-footprints.cu && ./texture-footprints
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
using morea::cuda::Check;
using morea::cuda::Texture3D;
using morea::cuda::TextureLayout;

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
  Float2x3D
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
  const int                 threads = 132 * 2048 * 4;
  morea::cuda::DeviceArray<float> buffer(threads);
  float *                         out = buffer.Data();
  cudaDeviceProp p{};
  cudaGetDeviceProperties(&p, 0);
  std::printf("%s; filtered fetches per second (1e9) by the edge of the cube a warp's lanes spread over\n", p.name);
  std::printf("%8s %12s %12s %12s %12s\n", "edge", "float 3D", "ushort 3D", "pair layers", "float2 3D");
  for (float spread : { 0.0f, 1.0f, 2.0f, 3.0f, 4.0f, 6.0f, 8.0f, 12.0f, 16.0f, 32.0f })
    std::printf("%8.0f %12.1f %12.1f %12.1f %12.1f\n", spread, 1e-9 * Rate<Float3D>(tf.Get(), spread, out, threads),
                1e-9 * Rate<Ushort3D>(tu.Get(), spread, out, threads),
                1e-9 * Rate<PairLayers>(tp.Get(), spread, out, threads),
                1e-9 * Rate<Float2x3D>(t2.Get(), spread, out, threads));
  return 0;
}

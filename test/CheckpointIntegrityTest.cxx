// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
// Checkpoints that cannot lie: a damaged, truncated or edited checkpoint, or
// one of another run, is refused with a message that says why, and the
// optimiser is left as it was. One test per kind of corruption; the edits are
// made once as they would happen (the checksum no longer matches) and once
// re-signed with a valid checksum, as a writer's bug or a deliberate edit
// would leave them, to reach the range checks behind the checksum.
#include "OptimiserTestProblem.h"

#include "morea_core/Error.h"
#include "morea_core/Hash.h"

#include <gtest/gtest.h>

#include <cstring>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>

using namespace morea_core;
using morea_test::OptimiserTestProblem;

namespace
{
constexpr std::size_t Generations = 10;
constexpr std::size_t SavedAt = 5;

/** A 10-generation run's checkpoint after generation 5, and what reads it. */
struct Saved
{
  OptimiserTestProblem               problem;
  std::unique_ptr<EvaluationBackend> backend = CreateCpuEvaluationBackend(*problem.evaluator, 2);
  std::string                        bytes;

  explicit Saved(const RunFingerprint & fingerprint = {})
  {
    MoRvGomea optimiser(problem.base, problem.topology, problem.parallel, *problem.constraint, *backend,
                        Options(fingerprint));
    optimiser.Initialize(problem.InitialPopulation(Options(fingerprint)));
    for (std::size_t g = 0; g < SavedAt; ++g)
      optimiser.RunGeneration();
    bytes = optimiser.CheckpointBytes();
  }
  GomeaOptions
  Options(const RunFingerprint & fingerprint = {}, std::size_t generations = Generations) const
  {
    GomeaOptions o = problem.Options(11, generations);
    o.fingerprint = fingerprint;
    return o;
  }
  /** Loads `file` into a fresh optimiser: "" when it loads, else the error's
   *  message; the optimiser must stay unloaded on an error. */
  std::string
  Load(const std::string & file, const RunFingerprint & fingerprint = {}, std::size_t generations = Generations,
       const TetrahedralMesh * base = nullptr)
  {
    MoRvGomea          optimiser(base ? *base : problem.base, problem.topology, problem.parallel, *problem.constraint, *backend,
                                 Options(fingerprint, generations));
    std::istringstream in(file);
    try
    {
      optimiser.Load(in);
    }
    catch (const Error & e)
    {
      EXPECT_EQ(optimiser.Generation(), 0u) << "a refused checkpoint changed the optimiser";
      EXPECT_TRUE(optimiser.Population().empty());
      return e.what();
    }
    EXPECT_EQ(optimiser.Generation(), SavedAt);
    return {};
  }
};

// The layout (MoRvGomeaCheckpoint.cxx): magic 8, version 4, payload length 8,
// the payload, XXH64 of all before it 8. The payload opens with the
// fingerprint (count, then key and value strings, each a length and bytes),
// seven counts, the generation, the next id, the reference point (3 doubles),
// then per solution: source points (count, points), target points, id.
constexpr std::size_t HeaderBytes = 20;

std::uint64_t
ReadU64(const std::string & bytes, std::size_t at)
{
  std::uint64_t v;
  std::memcpy(&v, bytes.data() + at, sizeof v);
  return v;
}
void
WriteU64(std::string & bytes, std::size_t at, std::uint64_t v)
{
  std::memcpy(&bytes[at], &v, sizeof v);
}
std::size_t
GenerationOffset(const std::string & bytes)
{
  std::size_t at = HeaderBytes;
  const std::uint64_t keys = ReadU64(bytes, at);
  at += 8;
  for (std::uint64_t k = 0; k < 2 * keys; ++k)
    at += 8 + ReadU64(bytes, at);
  return at + 7 * 8;
}
/** Where solution 0's id lies. */
std::size_t
FirstIdOffset(const std::string & bytes)
{
  std::size_t at = GenerationOffset(bytes) + 8 + 8 + 24;
  for (int side = 0; side < 2; ++side)
    at += 8 + 24 * ReadU64(bytes, at);
  return at;
}
/** The checksum made valid again for edited contents. */
std::string
Resigned(std::string bytes)
{
  WriteU64(bytes, bytes.size() - 8, Hash64(bytes.data(), bytes.size() - 8));
  return bytes;
}
bool
Contains(const std::string & text, const std::string & part)
{
  return text.find(part) != std::string::npos;
}

TEST(CheckpointIntegrity, TheUntouchedCheckpointLoadsAlsoForALongerRun)
{
  Saved saved;
  EXPECT_EQ(saved.Load(saved.bytes), "");
  EXPECT_EQ(saved.Load(saved.bytes, {}, 50), ""); // going on for longer is allowed
  EXPECT_EQ(ReadU64(saved.bytes, GenerationOffset(saved.bytes)), SavedAt);
  EXPECT_EQ(saved.Load(Resigned(saved.bytes)), "");
}

TEST(CheckpointIntegrity, RandomByteFlipsAreRefused)
{
  Saved           saved;
  std::mt19937_64 random(2026);
  std::size_t     damaged = 0;
  for (int trial = 0; trial < 300; ++trial)
  {
    std::string bytes = saved.bytes;
    const int   flips = 1 + static_cast<int>(random() % 4);
    for (int f = 0; f < flips; ++f)
      bytes[random() % bytes.size()] ^= static_cast<char>(1 + random() % 255);
    const std::string message = saved.Load(bytes);
    ASSERT_FALSE(message.empty()) << "trial " << trial << ": a damaged checkpoint loaded";
    EXPECT_TRUE(Contains(message, "damaged (its checksum does not match") || Contains(message, "not a MOREA checkpoint") ||
                Contains(message, "damaged (its header holds no format version)") ||
                Contains(message, "another version") || Contains(message, "truncated") ||
                Contains(message, "unexpected bytes after its end"))
      << message;
    damaged += Contains(message, "checksum");
  }
  EXPECT_GT(damaged, 250u); // most flips land in the payload
}

TEST(CheckpointIntegrity, AFlippedIdIsRefused)
{
  Saved             saved;
  const std::size_t at = FirstIdOffset(saved.bytes);
  const std::uint64_t id = ReadU64(saved.bytes, at);
  std::string       flipped = saved.bytes;
  WriteU64(flipped, at, id ^ (std::uint64_t{ 1 } << 40));
  EXPECT_TRUE(Contains(saved.Load(flipped), "damaged")) << saved.Load(flipped);
  const std::string resigned = saved.Load(Resigned(flipped));
  EXPECT_TRUE(Contains(resigned, "inconsistent (solution 0 has id")) << resigned;
  EXPECT_TRUE(Contains(resigned, "not given out yet")) << resigned;
  // Another solution's id: two solutions with one id.
  const std::size_t   next = at + 8 + sizeof(TetrahedronValues) + 8; // past the id, the totals and the stall count
  const std::size_t   secondId = next + 2 * (8 + 24 * ReadU64(saved.bytes, next));
  std::string         duplicate = saved.bytes;
  WriteU64(duplicate, secondId, id);
  const std::string   twice = saved.Load(Resigned(duplicate));
  EXPECT_TRUE(Contains(twice, "which another solution has")) << twice;
}

TEST(CheckpointIntegrity, AGenerationOutOfRangeIsRefused)
{
  Saved             saved;
  const std::size_t at = GenerationOffset(saved.bytes);
  for (std::uint64_t generation : { 2u, 11u, 9999u })
  {
    std::string edited = saved.bytes;
    WriteU64(edited, at, generation);
    const std::string unsigned_ = saved.Load(edited);
    EXPECT_TRUE(Contains(unsigned_, "damaged")) << generation << ": " << unsigned_;
    const std::string message = saved.Load(Resigned(edited));
    if (generation > Generations)
      EXPECT_TRUE(Contains(message, "holds generation " + std::to_string(generation) + ", beyond this run's 10 "
                                    "(ea_num_generations)"))
        << message;
    else
      EXPECT_TRUE(Contains(message, "a history of 6 generations at generation 2")) << message;
  }
}

TEST(CheckpointIntegrity, ATruncatedCheckpointIsRefused)
{
  Saved saved;
  for (std::size_t length : { std::size_t{ 0 }, std::size_t{ 5 }, std::size_t{ 12 }, HeaderBytes, HeaderBytes + 100,
                              saved.bytes.size() / 2, saved.bytes.size() - 8, saved.bytes.size() - 1 })
  {
    const std::string message = saved.Load(saved.bytes.substr(0, length));
    EXPECT_TRUE(length < 8 ? Contains(message, "not a MOREA checkpoint") : Contains(message, "the file is truncated"))
      << length << ": " << message;
  }
  const std::string longer = saved.Load(saved.bytes + "x");
  EXPECT_TRUE(Contains(longer, "1 unexpected bytes after its end")) << longer;
  // A payload cut short inside but with a consistent frame: caught by the reader.
  std::string cut = saved.bytes.substr(0, saved.bytes.size() - 8 - 100);
  WriteU64(cut, 12, cut.size() - HeaderBytes);
  cut += std::string(8, '\0');
  EXPECT_TRUE(Contains(saved.Load(Resigned(cut)), "payload ends early")) << saved.Load(Resigned(cut));
}

TEST(CheckpointIntegrity, AnotherFormatIsRefusedByName)
{
  Saved       saved;
  std::string older = saved.bytes;
  const std::uint32_t three = 3;
  std::memcpy(&older[8], &three, sizeof three);
  EXPECT_EQ(saved.Load(older), "checkpoint: written by another version of MOREA (format 3; this one reads format 4); "
                               "start afresh");
  std::string garbage = "MOREACKP but not a checkpoint";
  EXPECT_EQ(saved.Load(garbage), "checkpoint: the file is damaged (its header holds no format version); start afresh");
}

TEST(CheckpointIntegrity, AnotherRunsFingerprintIsRefusedNamingTheFirstKey)
{
  RunFingerprint written;
  written.Add("morea_sampling_rate", "0.25");
  written.Add("morea_elasticity_factors", "\"bones=10, bladder=0.5\"");
  written.AddHash("fixed image voxels", "abc", 3);
  Saved saved(written);
  EXPECT_EQ(saved.Load(saved.bytes, written), "");

  RunFingerprint rate = written;
  rate.Add("morea_sampling_rate", "0.5");
  const std::string message = saved.Load(saved.bytes, rate);
  EXPECT_TRUE(Contains(message, "it was written by a run with other inputs or parameters (morea_sampling_rate: 0.25 "
                                "in the checkpoint, 0.5 in this run); resume with those it was written with, or "
                                "start afresh"))
    << message;
  RunFingerprint both = rate;
  both.Add("morea_elasticity_factors", "\"bones=10\"");
  EXPECT_TRUE(Contains(saved.Load(saved.bytes, both), "(morea_sampling_rate: ")) << "the first key is named";
  RunFingerprint factors = written;
  factors.Add("morea_elasticity_factors", "\"bones=10\"");
  EXPECT_TRUE(Contains(saved.Load(saved.bytes, factors),
                       "morea_elasticity_factors: \"bones=10, bladder=0.5\" in the checkpoint, \"bones=10\" in this run"))
    << saved.Load(saved.bytes, factors);
  RunFingerprint image = written;
  image.AddHash("fixed image voxels", "abd", 3);
  EXPECT_TRUE(Contains(saved.Load(saved.bytes, image), "(fixed image voxels: xxh64:")) << saved.Load(saved.bytes, image);
  RunFingerprint more = written;
  more.Add("preprocess_isotropic_spacing", "1.5");
  EXPECT_TRUE(Contains(saved.Load(saved.bytes, more), "preprocess_isotropic_spacing: not in the checkpoint, 1.5 in this run"));
  // The optimiser's own entry: the mesh (one point moved by a micrometre).
  TetrahedralMesh moved = saved.problem.base;
  moved.points[moved.points.size() / 2][0] += 1e-3;
  const std::string mesh = saved.Load(saved.bytes, written, Generations, &moved);
  EXPECT_TRUE(Contains(mesh, "(mesh: " + std::to_string(moved.points.size()) + " points, ")) << mesh;
}

TEST(CheckpointIntegrity, AnotherEvaluationBackendIsRefusedByName)
{
  // The texture path's values differ from the CPU's by about 1e-4: a front
  // continued on the other would mix both. cuda-exact agrees with the CPU.
  RunFingerprint onTexture, onCpu, onExact;
  onTexture.AddEvaluationBackend("cuda-texture");
  onCpu.AddEvaluationBackend("cpu");
  onExact.AddEvaluationBackend("cuda-exact");
  Saved saved(onTexture);
  EXPECT_EQ(saved.Load(saved.bytes, onTexture), "");
  const std::string message = saved.Load(saved.bytes, onCpu);
  EXPECT_TRUE(Contains(message, "(evaluation backend: cuda-texture (the texture units' interpolation) in the "
                                "checkpoint, cpu or cuda-exact (exact interpolation) in this run)"))
    << message;
  Saved onCpuSaved(onCpu);
  EXPECT_EQ(onCpuSaved.Load(onCpuSaved.bytes, onExact), "");
}

TEST(CheckpointIntegrity, FilesAreWholeAndErrorsNameThem)
{
  Saved                       saved;
  const std::filesystem::path dir = std::filesystem::temp_directory_path() / "morea-checkpoint-integrity-test";
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  const std::string path = (dir / "checkpoint.bin").string();
  {
    MoRvGomea optimiser(saved.problem.base, saved.problem.topology, saved.problem.parallel, *saved.problem.constraint,
                        *saved.backend, saved.Options());
    std::istringstream in(saved.bytes);
    optimiser.Load(in);
    optimiser.SaveCheckpoint(path);
  }
  EXPECT_FALSE(std::filesystem::exists(path + ".partial"));
  std::ifstream     in(path, std::ios::binary);
  const std::string onDisk((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  EXPECT_EQ(onDisk, saved.bytes);
  std::ofstream(path, std::ios::binary | std::ios::trunc).write(onDisk.data(), 1000);
  MoRvGomea optimiser(saved.problem.base, saved.problem.topology, saved.problem.parallel, *saved.problem.constraint,
                      *saved.backend, saved.Options());
  try
  {
    optimiser.LoadCheckpoint(path);
    ADD_FAILURE() << "a truncated file loaded";
  }
  catch (const Error & e)
  {
    EXPECT_EQ(std::string(e.what()).rfind("checkpoint " + path + ": the file is truncated (1000 bytes", 0), 0u)
      << e.what();
  }
  std::filesystem::remove_all(dir);
}
} // namespace

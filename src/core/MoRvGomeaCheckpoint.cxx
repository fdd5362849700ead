// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
// Checkpoints of MO-RV-GOMEA: the population (with its accumulated objective
// totals, which a fresh evaluation would reproduce only to rounding), ids,
// stall counters, the archive, the adaptive distribution state, the history
// and the generation counter. The generator needs no state: generation g
// draws from (seed, g). Per-tetrahedron values are recomputed on load; the
// evaluation is deterministic, so they come back bit for bit.
//
// A checkpoint must not lie: a resume from a damaged file, or from another
// run's, would end with a front that looks right and is not. So the file is
//   magic (8 bytes), format version (4), payload length (8), payload,
//   XXH64 of everything before it (8),
// (the checksum takes about 7 ms per 50 MB, on the optimiser's thread),
// the payload begins with the run's fingerprint (key = value entries: the
// inputs, parameters and mesh the front depends on), and what the payload
// holds is checked against this run's mesh and options before any of it is
// used.
#include "morea_core/CheckpointWriter.h"
#include "morea_core/Error.h"
#include "morea_core/Hash.h"
#include "morea_core/MoRvGomea.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <fstream>
#include <istream>
#include <limits>
#include <ostream>
#include <streambuf>
#include <iterator>
#include <set>
#include <string>

namespace morea_core
{
namespace
{
constexpr char          Magic[8] = { 'M', 'O', 'R', 'E', 'A', 'C', 'K', 'P' };
// 2: GenerationRecord has device kernel seconds and samples; 3: and the device
// span; 4: payload length, checksum and fingerprint.
constexpr std::uint32_t Version = 4;
constexpr std::size_t   HeaderBytes = sizeof Magic + sizeof(std::uint32_t) + sizeof(std::uint64_t);
constexpr std::size_t   ChecksumBytes = sizeof(std::uint64_t);

class Writer
{
public:
  explicit Writer(std::ostream & out)
    : m_Out(out)
  {}
  template <typename T>
  void
  Put(const T & v)
  {
    static_assert(std::is_trivially_copyable<T>::value, "plain values only");
    m_Out.write(reinterpret_cast<const char *>(&v), sizeof v);
  }
  void
  PutSize(std::size_t n)
  {
    Put(static_cast<std::uint64_t>(n));
  }
  void
  PutString(const std::string & text)
  {
    PutSize(text.size());
    m_Out.write(text.data(), static_cast<std::streamsize>(text.size()));
  }
  void
  PutPoints(const std::vector<Vec3> & p)
  {
    PutSize(p.size());
    m_Out.write(reinterpret_cast<const char *>(p.data()), static_cast<std::streamsize>(p.size() * sizeof(Vec3)));
  }
  void
  PutDoubles(const std::vector<double> & v)
  {
    PutSize(v.size());
    m_Out.write(reinterpret_cast<const char *>(v.data()), static_cast<std::streamsize>(v.size() * sizeof(double)));
  }
  void
  PutFitness(const Fitness & f)
  {
    Put(f.objectives);
    Put(static_cast<std::uint8_t>(f.feasible));
    Put(f.constraint);
  }

private:
  std::ostream & m_Out;
};

/** Reads the payload from memory; every read checks that the bytes are there. */
class Reader
{
public:
  Reader(const char * begin, const char * end)
    : m_At(begin)
    , m_End(end)
  {}
  template <typename T>
  T
  Get()
  {
    static_assert(std::is_trivially_copyable<T>::value, "plain values only");
    T v;
    Take(&v, sizeof v);
    return v;
  }
  std::size_t
  GetSize(std::size_t limit)
  {
    const auto n = Get<std::uint64_t>();
    if (n > limit)
      throw Error("checkpoint: the file is corrupt (a count of " + std::to_string(n) + ")");
    return static_cast<std::size_t>(n);
  }
  std::string
  GetString(std::size_t limit)
  {
    std::string text(GetSize(limit), '\0');
    Take(&text[0], text.size());
    return text;
  }
  std::vector<Vec3>
  GetPoints(std::size_t expected)
  {
    const std::size_t n = GetSize(std::numeric_limits<std::uint32_t>::max());
    if (n != expected)
      throw Error("checkpoint: a mesh has " + std::to_string(n) + " points, this problem " + std::to_string(expected));
    std::vector<Vec3> p(n);
    Take(p.data(), n * sizeof(Vec3));
    for (const Vec3 & x : p)
      if (!std::isfinite(x[0]) || !std::isfinite(x[1]) || !std::isfinite(x[2]))
        throw Error("checkpoint: the file is corrupt (a point that is not a finite number)");
    return p;
  }
  std::vector<double>
  GetDoubles(std::size_t limit)
  {
    std::vector<double> v(GetSize(limit));
    Take(v.data(), v.size() * sizeof(double));
    return v;
  }
  Fitness
  GetFitness()
  {
    Fitness f;
    f.objectives = Get<ObjectiveVector>();
    f.feasible = Get<std::uint8_t>() != 0;
    f.constraint = Get<double>();
    return f;
  }
  bool
  AtEnd() const
  {
    return m_At == m_End;
  }

private:
  void
  Take(void * to, std::size_t n)
  {
    if (static_cast<std::size_t>(m_End - m_At) < n)
      throw Error("checkpoint: the file is corrupt (its payload ends early)");
    if (n == 0) // an empty vector's data() may be null, which memcpy must not get
      return;
    std::memcpy(to, m_At, n);
    m_At += n;
  }
  const char * m_At;
  const char * m_End;
};

/** "checkpoint: <why>" as "checkpoint <path>: <why>". */
Error
NamingFile(const Error & e, const std::string & path)
{
  const std::string message = e.what();
  const std::string prefix = "checkpoint: ";
  return Error(message.rfind(prefix, 0) == 0 ? "checkpoint " + path + ": " + message.substr(prefix.size())
                                             : "checkpoint " + path + ": " + message);
}
} // namespace

RunFingerprint
MoRvGomea::Fingerprint() const
{
  RunFingerprint fingerprint = m_Options.fingerprint;
  const std::uint64_t tetrahedra = Hash64(m_Base.tetrahedra.data(), m_Base.tetrahedra.size() * sizeof(Tetrahedron));
  fingerprint.Add("mesh", std::to_string(m_Base.points.size()) + " points, " + std::to_string(m_Base.tetrahedra.size()) +
                            " tetrahedra, xxh64:" +
                            HashText(Hash64(m_Base.points.data(), m_Base.points.size() * sizeof(Vec3), tetrahedra)));
  return fingerprint;
}

void
MoRvGomea::WritePayload(std::ostream & out) const
{
  Writer w(out);
  const RunFingerprint fingerprint = Fingerprint();
  w.PutSize(fingerprint.Entries().size());
  for (const auto & [key, value] : fingerprint.Entries())
  {
    w.PutString(key);
    w.PutString(value);
  }
  // What the checkpoint belongs to: resuming another problem is an error.
  w.PutSize(m_Topology.NumberOfPoints());
  w.PutSize(m_Topology.NumberOfTetrahedra());
  w.PutSize(m_Parallel.elements.size());
  w.PutSize(m_Options.populationSize);
  w.PutSize(m_Options.numberOfClusters);
  w.PutSize(m_Options.archiveCapacity);
  w.Put(m_Options.seed);

  w.PutSize(m_Generation);
  w.Put(m_NextId);
  w.Put(m_Reference);
  for (std::size_t s = 0; s < m_Population.size(); ++s)
  {
    w.PutPoints(m_Population[s].source);
    w.PutPoints(m_Population[s].target);
    w.Put(m_Ids[s]);
    w.Put(m_Totals[s].sum);
    w.PutSize(m_NoImprovement[s]);
  }
  w.Put(static_cast<std::uint8_t>(m_Archive->IsDiscretised()));
  w.Put(m_Archive->CellWidths());
  w.PutSize(m_Archive->Size());
  for (const auto & e : m_Archive->Entries())
  {
    w.PutFitness(e.fitness);
    w.Put(e.id);
    w.PutPoints(e.solution.source);
    w.PutPoints(e.solution.target);
  }
  w.PutSize(m_Distributions.size());
  for (const auto & cluster : m_Distributions)
  {
    w.PutSize(cluster.size());
    for (const auto & d : cluster)
    {
      w.PutDoubles(d.previousMean);
      w.Put(d.multiplier);
      w.PutSize(d.noImprovementStretch);
    }
  }
  w.PutSize(m_ClusterMeans.size());
  for (const auto & m : m_ClusterMeans)
    w.Put(m);
  w.PutSize(m_History.size());
  for (const auto & r : m_History)
    w.Put(r);
  if (!out)
    throw Error("checkpoint: writing failed");
}

void
MoRvGomea::Save(std::ostream & out) const
{
  const std::string bytes = CheckpointBytes();
  out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  if (!out)
    throw Error("checkpoint: writing failed");
}

void
MoRvGomea::Load(std::istream & in)
{
  const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  LoadBytes(bytes);
}

void
MoRvGomea::LoadBytes(const std::string & bytes)
{
  // The frame: magic, version, length, checksum.
  if (bytes.size() < sizeof Magic || std::memcmp(bytes.data(), Magic, sizeof Magic) != 0)
    throw Error("checkpoint: not a MOREA checkpoint");
  std::uint32_t version = 0;
  std::uint64_t length = 0;
  if (bytes.size() < HeaderBytes)
    throw Error("checkpoint: the file is truncated (" + std::to_string(bytes.size()) + " bytes)");
  std::memcpy(&version, bytes.data() + sizeof Magic, sizeof version);
  if (version == 0 || version > 1000)
    throw Error("checkpoint: the file is damaged (its header holds no format version); start afresh");
  if (version != Version)
    throw Error("checkpoint: written by another version of MOREA (format " + std::to_string(version) +
                "; this one reads format " + std::to_string(Version) + "); start afresh");
  std::memcpy(&length, bytes.data() + sizeof Magic + sizeof version, sizeof length);
  const std::size_t available = bytes.size() - HeaderBytes;
  if (length > available || available - length < ChecksumBytes)
    throw Error("checkpoint: the file is truncated (" + std::to_string(bytes.size()) +
                " bytes; its header announces " + std::to_string(length) + " bytes of state and a checksum)");
  if (available - length > ChecksumBytes)
    throw Error("checkpoint: the file has " + std::to_string(available - length - ChecksumBytes) +
                " unexpected bytes after its end");
  std::uint64_t checksum = 0;
  std::memcpy(&checksum, bytes.data() + HeaderBytes + length, sizeof checksum);
  if (checksum != Hash64(bytes.data(), HeaderBytes + length))
    throw Error("checkpoint: the file is damaged (its checksum does not match its contents); start afresh");

  // The run it belongs to.
  Reader r(bytes.data() + HeaderBytes, bytes.data() + HeaderBytes + length);
  RunFingerprint saved;
  const std::size_t keys = r.GetSize(1u << 16);
  for (std::size_t i = 0; i < keys; ++i)
  {
    std::string key = r.GetString(1u << 16);
    saved.Add(key, r.GetString(1u << 20));
  }
  const std::string difference = saved.FirstDifference(Fingerprint());
  if (!difference.empty())
    throw Error("checkpoint: it was written by a run with other inputs or parameters (" + difference +
                "); resume with those it was written with, or start afresh");
  const std::size_t big = std::numeric_limits<std::uint32_t>::max();
  auto              expect = [&](std::size_t value, const char * what) {
    const std::size_t saved = r.GetSize(big);
    if (saved != value)
      throw Error(std::string("checkpoint: it has ") + std::to_string(saved) + " " + what + ", this run " +
                  std::to_string(value));
  };
  expect(m_Topology.NumberOfPoints(), "mesh points");
  expect(m_Topology.NumberOfTetrahedra(), "tetrahedra");
  expect(m_Parallel.elements.size(), "FOS elements");
  expect(m_Options.populationSize, "solutions (ea_population_size)");
  expect(m_Options.numberOfClusters, "clusters (ea_num_clusters)");
  expect(m_Options.archiveCapacity, "archive places (ea_archive_size)");
  if (r.Get<std::uint64_t>() != m_Options.seed)
    throw Error("checkpoint: it was written with another seed");

  // The state; range checks as it comes.
  const auto corrupt = [](const std::string & what) { return Error("checkpoint: the file is inconsistent (" + what + ")"); };
  const std::size_t generation = r.GetSize(big);
  if (generation > m_Options.generations)
    throw Error("checkpoint: it holds generation " + std::to_string(generation) + ", beyond this run's " +
                std::to_string(m_Options.generations) + " (ea_num_generations)");
  const auto        nextId = r.Get<std::uint64_t>();
  const auto        reference = r.Get<ObjectiveVector>();
  if (nextId < m_Options.populationSize)
    throw corrupt("ids given out: " + std::to_string(nextId) + ", fewer than the population");
  const std::size_t points = m_Topology.NumberOfPoints();
  std::vector<DualMesh>        population(m_Options.populationSize);
  std::vector<std::uint64_t>   ids(population.size());
  std::vector<ObjectiveTotals> totals(population.size());
  std::vector<std::size_t>     stalls(population.size());
  std::set<std::uint64_t>      seen;
  for (std::size_t s = 0; s < population.size(); ++s)
  {
    population[s].source = r.GetPoints(points);
    population[s].target = r.GetPoints(points);
    ids[s] = r.Get<std::uint64_t>();
    if (ids[s] >= nextId || !seen.insert(ids[s]).second)
      throw corrupt("solution " + std::to_string(s) + " has id " + std::to_string(ids[s]) +
                    (ids[s] >= nextId ? ", not given out yet (" + std::to_string(nextId) + " were)"
                                      : ", which another solution has"));
    totals[s].sum = r.Get<TetrahedronValues>();
    stalls[s] = r.GetSize(big);
    if (stalls[s] > generation)
      throw corrupt("solution " + std::to_string(s) + " stalled for " + std::to_string(stalls[s]) +
                    " generations of " + std::to_string(generation));
  }
  const bool        discretised = r.Get<std::uint8_t>() != 0;
  const auto        cellWidths = r.Get<ObjectiveVector>();
  const std::size_t archiveSize = r.GetSize(m_Options.archiveCapacity);
  std::vector<ArchiveEntry> entries(archiveSize);
  for (auto & e : entries)
  {
    e.fitness = r.GetFitness();
    e.id = r.Get<std::uint64_t>();
    if (e.id >= nextId)
      throw corrupt("an archived solution has id " + std::to_string(e.id) + ", not given out yet (" +
                    std::to_string(nextId) + " were)");
    e.solution.source = r.GetPoints(points);
    e.solution.target = r.GetPoints(points);
  }
  const std::size_t elements = m_Parallel.elements.size();
  std::vector<std::vector<DistributionState>> distributions(r.GetSize(m_Options.numberOfClusters + NumberOfObjectives));
  for (auto & cluster : distributions)
  {
    cluster.resize(r.GetSize(big));
    if (cluster.size() != elements)
      throw corrupt("a cluster has distributions for " + std::to_string(cluster.size()) + " FOS elements of " +
                    std::to_string(elements));
    for (std::size_t e = 0; e < elements; ++e)
    {
      DistributionState & d = cluster[e];
      d.previousMean = r.GetDoubles(1u << 16);
      const std::size_t dimension = 6 * m_Parallel.elements[e].points.size();
      if (!d.previousMean.empty() && d.previousMean.size() != dimension)
        throw corrupt("a distribution mean of " + std::to_string(d.previousMean.size()) + " variables for an element of " +
                      std::to_string(dimension));
      d.multiplier = r.Get<double>();
      if (!(d.multiplier > 0.0) || !std::isfinite(d.multiplier))
        throw corrupt("a distribution multiplier of " + std::to_string(d.multiplier));
      d.noImprovementStretch = r.GetSize(big);
    }
  }
  std::vector<ObjectiveVector> clusterMeans(r.GetSize(distributions.size()));
  if (clusterMeans.size() != distributions.size())
    throw corrupt(std::to_string(clusterMeans.size()) + " cluster means for " + std::to_string(distributions.size()) +
                  " clusters");
  for (auto & m : clusterMeans)
    m = r.Get<ObjectiveVector>();
  // The history starts at this optimiser's first generation (a mesh level's).
  const std::size_t first = m_Options.firstGeneration;
  if (generation < first)
    throw corrupt("generation " + std::to_string(generation) + ", before this mesh level's first, " +
                  std::to_string(first));
  std::vector<GenerationRecord> history(r.GetSize(big));
  if (history.size() != generation - first + 1)
    throw corrupt("a history of " + std::to_string(history.size()) + " generations at generation " +
                  std::to_string(generation));
  for (std::size_t g = 0; g < history.size(); ++g)
  {
    history[g] = r.Get<GenerationRecord>();
    if (history[g].generation != first + g)
      throw corrupt("generation " + std::to_string(first + g) + " of the history says it is generation " +
                    std::to_string(history[g].generation));
  }
  if (!r.AtEnd())
    throw corrupt("data after the end of the state");

  // Everything read and checked: now replace the state.
  m_Generation = generation;
  m_NextId = nextId;
  m_Reference = reference;
  m_Population = std::move(population);
  m_Ids = std::move(ids);
  RenewKeySalt();
  m_NoImprovement = std::move(stalls);
  m_TetValues.assign(m_Population.size(), {});
  m_Totals.assign(m_Population.size(), ObjectiveTotals{});
  EvaluatePopulationFully();
  m_Totals = std::move(totals);
  m_Archive->Restore(std::move(entries), discretised, cellWidths);
  m_Distributions = std::move(distributions);
  m_ClusterMeans = std::move(clusterMeans);
  m_History = std::move(history);
  m_SteeringLimit = std::numeric_limits<double>::infinity();
}

std::string
MoRvGomea::CheckpointBytes() const
{
  std::string bytes;
  CheckpointBytes(bytes);
  return bytes;
}

void
MoRvGomea::CheckpointBytes(std::string & bytes) const
{
  if (m_Population.empty())
    throw Error("checkpoint: the optimiser has not been initialised");
  // Appends straight to the string (an ostringstream would copy it once more).
  class StringSink : public std::streambuf
  {
  public:
    explicit StringSink(std::string & s)
      : m_String(s)
    {}

  protected:
    std::streamsize
    xsputn(const char * p, std::streamsize n) override
    {
      m_String.append(p, static_cast<std::size_t>(n));
      return n;
    }
    int_type
    overflow(int_type c) override
    {
      if (!traits_type::eq_int_type(c, traits_type::eof()))
        m_String.push_back(traits_type::to_char_type(c));
      return traits_type::not_eof(c);
    }

  private:
    std::string & m_String;
  };
  bytes.clear();
  // Solutions dominate the size: the population's and the archive's points.
  const std::size_t solutions = m_Population.size() + m_Archive->Size();
  bytes.reserve(solutions * (2 * m_Topology.NumberOfPoints() * sizeof(Vec3) + 128) + (1u << 20));
  bytes.append(Magic, sizeof Magic);
  bytes.append(reinterpret_cast<const char *>(&Version), sizeof Version);
  bytes.append(sizeof(std::uint64_t), '\0'); // the payload's length, once known
  StringSink   sink(bytes);
  std::ostream out(&sink);
  WritePayload(out);
  const std::uint64_t length = bytes.size() - HeaderBytes;
  std::memcpy(&bytes[sizeof Magic + sizeof Version], &length, sizeof length);
  const std::uint64_t checksum = Hash64(bytes.data(), bytes.size());
  bytes.append(reinterpret_cast<const char *>(&checksum), sizeof checksum);
}

void
MoRvGomea::SaveCheckpoint(const std::string & path) const
{
  WriteFileAtomically(path, CheckpointBytes());
}

void
MoRvGomea::LoadCheckpoint(const std::string & path)
{
  std::ifstream in(path, std::ios::binary | std::ios::ate);
  if (!in)
    throw Error("checkpoint " + path + ": cannot be read");
  // In one read (a checkpoint of the paper's configuration is about 50 MB).
  std::string bytes(static_cast<std::size_t>(std::max<std::streamoff>(0, in.tellg())), '\0');
  in.seekg(0);
  if (!in.read(&bytes[0], static_cast<std::streamsize>(bytes.size())))
    throw Error("checkpoint " + path + ": cannot be read");
  try
  {
    LoadBytes(bytes);
  }
  catch (const Error & e)
  {
    throw NamingFile(e, path);
  }
}
} // namespace morea_core

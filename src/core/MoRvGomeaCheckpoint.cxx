// Checkpoints of MO-RV-GOMEA: the population (with its accumulated objective
// totals, which a fresh evaluation would reproduce only to rounding), ids,
// stall counters, the archive, the adaptive distribution state, the history
// and the generation counter. The generator needs no state: generation g
// draws from (seed, g). Per-tetrahedron values are recomputed on load; the
// evaluation is deterministic, so they come back bit for bit.
#include "morea/CheckpointWriter.h"
#include "morea/Error.h"
#include "morea/MoRvGomea.h"

#include <cstring>
#include <fstream>
#include <istream>
#include <limits>
#include <ostream>
#include <streambuf>
#include <string>

namespace morea
{
namespace
{
constexpr char          Magic[8] = { 'M', 'O', 'R', 'E', 'A', 'C', 'K', 'P' };
constexpr std::uint32_t Version = 3; // 2: GenerationRecord has device kernel seconds and samples; 3: and the device span

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

class Reader
{
public:
  explicit Reader(std::istream & in)
    : m_In(in)
  {}
  template <typename T>
  T
  Get()
  {
    T v;
    m_In.read(reinterpret_cast<char *>(&v), sizeof v);
    if (!m_In)
      throw Error("checkpoint: the file is truncated");
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
  std::vector<Vec3>
  GetPoints(std::size_t expected)
  {
    const std::size_t n = GetSize(expected);
    if (n != expected)
      throw Error("checkpoint: a mesh has " + std::to_string(n) + " points, this problem " + std::to_string(expected));
    std::vector<Vec3> p(n);
    m_In.read(reinterpret_cast<char *>(p.data()), static_cast<std::streamsize>(n * sizeof(Vec3)));
    if (!m_In)
      throw Error("checkpoint: the file is truncated");
    return p;
  }
  std::vector<double>
  GetDoubles(std::size_t limit)
  {
    std::vector<double> v(GetSize(limit));
    m_In.read(reinterpret_cast<char *>(v.data()), static_cast<std::streamsize>(v.size() * sizeof(double)));
    if (!m_In)
      throw Error("checkpoint: the file is truncated");
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

private:
  std::istream & m_In;
};
} // namespace

void
MoRvGomea::Save(std::ostream & out) const
{
  if (m_Population.empty())
    throw Error("checkpoint: the optimiser has not been initialised");
  Writer w(out);
  out.write(Magic, sizeof Magic);
  w.Put(Version);
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
MoRvGomea::Load(std::istream & in)
{
  char magic[sizeof Magic];
  in.read(magic, sizeof magic);
  if (!in || std::memcmp(magic, Magic, sizeof Magic) != 0)
    throw Error("checkpoint: not a MOREA checkpoint");
  Reader r(in);
  if (r.Get<std::uint32_t>() != Version)
    throw Error("checkpoint: written by another version");
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

  const std::size_t generation = r.GetSize(big);
  const auto        nextId = r.Get<std::uint64_t>();
  const auto        reference = r.Get<ObjectiveVector>();
  const std::size_t points = m_Topology.NumberOfPoints();
  std::vector<DualMesh>        population(m_Options.populationSize);
  std::vector<std::uint64_t>   ids(population.size());
  std::vector<ObjectiveTotals> totals(population.size());
  std::vector<std::size_t>     stalls(population.size());
  for (std::size_t s = 0; s < population.size(); ++s)
  {
    population[s].source = r.GetPoints(points);
    population[s].target = r.GetPoints(points);
    ids[s] = r.Get<std::uint64_t>();
    totals[s].sum = r.Get<TetrahedronValues>();
    stalls[s] = r.GetSize(big);
  }
  const bool        discretised = r.Get<std::uint8_t>() != 0;
  const auto        cellWidths = r.Get<ObjectiveVector>();
  const std::size_t archiveSize = r.GetSize(m_Options.archiveCapacity);
  std::vector<ArchiveEntry> entries(archiveSize);
  for (auto & e : entries)
  {
    e.fitness = r.GetFitness();
    e.id = r.Get<std::uint64_t>();
    e.solution.source = r.GetPoints(points);
    e.solution.target = r.GetPoints(points);
  }
  std::vector<std::vector<DistributionState>> distributions(r.GetSize(1u << 20));
  for (auto & cluster : distributions)
  {
    cluster.resize(r.GetSize(m_Parallel.elements.size()));
    for (auto & d : cluster)
    {
      d.previousMean = r.GetDoubles(1u << 16);
      d.multiplier = r.Get<double>();
      d.noImprovementStretch = r.GetSize(big);
    }
  }
  std::vector<ObjectiveVector> clusterMeans(r.GetSize(1u << 20));
  for (auto & m : clusterMeans)
    m = r.Get<ObjectiveVector>();
  std::vector<GenerationRecord> history(r.GetSize(big));
  for (auto & h : history)
    h = r.Get<GenerationRecord>();
  if (in.peek() != std::char_traits<char>::eof())
    throw Error("checkpoint: unexpected data after the end");

  // Everything read: now replace the state.
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
  StringSink   sink(bytes);
  std::ostream out(&sink);
  Save(out);
}

void
MoRvGomea::SaveCheckpoint(const std::string & path) const
{
  WriteFileAtomically(path, CheckpointBytes());
}

void
MoRvGomea::LoadCheckpoint(const std::string & path)
{
  std::ifstream in(path, std::ios::binary);
  if (!in)
    throw Error("checkpoint: cannot read " + path);
  Load(in);
}
} // namespace morea

#include "morea/ElitistArchive.h"

#include "morea/Error.h"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <string>

namespace morea
{
namespace
{
constexpr std::size_t M = NumberOfObjectives;
using Cell = std::array<double, M>;

// Grid cells are centred on multiples of the width (origin at -width/2) rather
// than starting at 0: the grid then depends on the widths alone, so Restore()
// needs nothing more, and widening always ends, because once a width exceeds
// twice every |value| all values share cell 0. A grid with a boundary at 0
// could never merge values of both signs, which a small capacity may need.
// A width of 0 (an objective with no range) leaves that objective out.
Cell
CellOf(const ObjectiveVector & x, const ObjectiveVector & widths)
{
  Cell cell{};
  for (std::size_t j = 0; j < M; ++j)
    cell[j] = widths[j] > 0.0 ? std::floor(x[j] / widths[j] + 0.5) : 0.0;
  return cell;
}

/** Squared distance from the cell's lower corner, in cell widths. */
double
DistanceToCellCorner(const ObjectiveVector & x, const ObjectiveVector & widths)
{
  const Cell cell = CellOf(x, widths);
  double     d = 0.0;
  for (std::size_t j = 0; j < M; ++j)
    if (widths[j] > 0.0)
    {
      const double offset = x[j] / widths[j] + 0.5 - cell[j];
      d += offset * offset;
    }
  return d;
}

/** Luong & Bosman's cell widths: the entries' range split into about
 *  capacity^(1/(M-1)) cells per objective, so a (M-1)-dimensional front
 *  covers about `capacity` cells. */
ObjectiveVector
InitialCellWidths(const std::vector<ArchiveEntry> & entries, std::size_t capacity)
{
  ObjectiveVector lower = entries.front().fitness.objectives;
  ObjectiveVector upper = lower;
  for (const ArchiveEntry & e : entries)
    for (std::size_t j = 0; j < M; ++j)
    {
      lower[j] = std::min(lower[j], e.fitness.objectives[j]);
      upper[j] = std::max(upper[j], e.fitness.objectives[j]);
    }
  const double    cellsPerObjective = std::pow(static_cast<double>(capacity), 1.0 / static_cast<double>(M - 1));
  ObjectiveVector widths{};
  for (std::size_t j = 0; j < M; ++j)
    widths[j] = (upper[j] - lower[j]) / cellsPerObjective;
  return widths;
}

/** Which entries stay when each cell may hold one: the one that dominates the
 *  others, else the one nearest the cell's lower corner (the earlier on ties). */
std::vector<bool>
OnePerCell(const std::vector<ArchiveEntry> & entries, const ObjectiveVector & widths)
{
  std::vector<Cell> cells;
  cells.reserve(entries.size());
  for (const ArchiveEntry & e : entries)
    cells.push_back(CellOf(e.fitness.objectives, widths));
  std::vector<std::size_t> order(entries.size());
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return cells[a] < cells[b]; });

  std::vector<bool> keep(entries.size(), false);
  for (std::size_t first = 0; first < order.size();)
  {
    std::size_t best = order[first];
    std::size_t next = first + 1;
    for (; next < order.size() && cells[order[next]] == cells[best]; ++next)
    {
      const ObjectiveVector & challenger = entries[order[next]].fitness.objectives;
      const ObjectiveVector & holder = entries[best].fitness.objectives;
      if (Dominates(challenger, holder) ||
          (!Dominates(holder, challenger) &&
           DistanceToCellCorner(challenger, widths) < DistanceToCellCorner(holder, widths)))
        best = order[next];
    }
    keep[best] = true;
    first = next;
  }
  return keep;
}

bool
AllFinite(const ObjectiveVector & v)
{
  return std::all_of(v.begin(), v.end(), [](double x) { return std::isfinite(x); });
}
} // namespace

ElitistArchive::ElitistArchive(std::size_t capacity)
  : m_Capacity(capacity)
{
  if (capacity == 0)
    throw Error("elitist archive: the capacity must be at least 1");
}

bool
ElitistArchive::Accepts(const Fitness & f) const
{
  // Non-finite objectives would make dominance meaningless, so they never enter.
  if (!f.feasible || !AllFinite(f.objectives))
    return false;
  const Cell cell = m_Discretised ? CellOf(f.objectives, m_CellWidths) : Cell{};
  auto       rejects = [&](const ArchiveEntry & e) {
    const ObjectiveVector & y = e.fitness.objectives;
    if (y == f.objectives || Dominates(y, f.objectives))
      return true;
    return m_Discretised && CellOf(y, m_CellWidths) == cell && !Dominates(f.objectives, y);
  };
  // The optimiser asks about many near-copies of one solution in a row, and
  // the entry that turned one away usually turns away the next: trying it
  // first saves the scan without changing the answer.
  if (m_RejectorHint < m_Entries.size() && rejects(m_Entries[m_RejectorHint]))
    return false;
  for (std::size_t i = 0; i < m_Entries.size(); ++i)
    if (rejects(m_Entries[i]))
    {
      m_RejectorHint = i;
      return false;
    }
  return true;
}

bool
ElitistArchive::Insert(const Fitness & f, const DualMesh & solution, std::uint64_t id)
{
  if (!Accepts(f))
    return false;
  RemoveIf([&](const ArchiveEntry & e) { return Dominates(f.objectives, e.fitness.objectives); });
  m_Entries.push_back(ArchiveEntry{ f, solution, id });
  if (m_Entries.size() <= m_Capacity)
    return true;

  // Over capacity: (re)discretise with widths from the current range, so the
  // grid follows the front as it moves, then widen until one per cell fits.
  // Each try thins the full set rather than the previous try's survivors: the
  // grids of different widths are not nested, and thinning the full set keeps
  // every dropped entry in a cell of a kept one, so Accepts() rejects it later.
  m_Discretised = true;
  m_CellWidths = InitialCellWidths(m_Entries, m_Capacity);
  std::vector<bool> keep = OnePerCell(m_Entries, m_CellWidths);
  while (static_cast<std::size_t>(std::count(keep.begin(), keep.end(), true)) > m_Capacity)
  {
    for (double & w : m_CellWidths)
      w *= 1.1;
    keep = OnePerCell(m_Entries, m_CellWidths);
  }
  const bool  newcomerKept = keep.back();
  std::size_t kept = 0;
  for (std::size_t i = 0; i < m_Entries.size(); ++i)
    if (keep[i])
    {
      if (kept != i) // a self-move would empty the meshes
        m_Entries[kept] = std::move(m_Entries[i]);
      ++kept;
    }
  m_Entries.resize(kept);
  // A newcomer thinned out at once did not improve the archive: report false.
  return newcomerKept;
}

void
ElitistArchive::RemoveIf(const std::function<bool(const ArchiveEntry &)> & remove)
{
  m_Entries.erase(std::remove_if(m_Entries.begin(), m_Entries.end(), remove), m_Entries.end());
}

std::vector<ObjectiveVector>
ElitistArchive::Objectives() const
{
  std::vector<ObjectiveVector> objectives;
  objectives.reserve(m_Entries.size());
  for (const ArchiveEntry & e : m_Entries)
    objectives.push_back(e.fitness.objectives);
  return objectives;
}

void
ElitistArchive::Restore(std::vector<ArchiveEntry> entries, bool discretised, const ObjectiveVector & cellWidths)
{
  if (entries.size() > m_Capacity)
    throw Error("elitist archive: cannot restore " + std::to_string(entries.size()) + " entries into a capacity of " +
                std::to_string(m_Capacity));
  m_Entries = std::move(entries);
  m_Discretised = discretised;
  m_CellWidths = cellWidths;
}
} // namespace morea

// MultiObjectiveRegistration core: mesh folds (SPEC 5, constraint). A mesh has
// folded where a tetrahedron's signed volume no longer has the sign it had in
// the base mesh; the constraint value is the sum of the folded tetrahedra's
// |signed volume| over both meshes. Feasible means no folded tetrahedron.
#ifndef morea_FoldConstraint_h
#define morea_FoldConstraint_h

#include "morea/TetrahedralMesh.h"

#include <cstdint>
#include <vector>

namespace morea
{
/** Per mesh: the folded tetrahedra's count and total |signed volume| (mm^3).
 *  The count decides feasibility exactly; the value ranks infeasible solutions. */
struct FoldViolation
{
  double      value{ 0.0 };
  std::size_t folded{ 0 };

  bool
  Feasible() const
  {
    return folded == 0;
  }
  FoldViolation &
  operator+=(const FoldViolation & o)
  {
    value += o.value;
    folded += o.folded;
    return *this;
  }
};

class FoldConstraint
{
public:
  /** Reference signs from the base configuration `reference`. */
  FoldConstraint(const MeshTopology & topology, const std::vector<Vec3> & reference);

  /** |signed volume| of tetrahedron t in `points` when folded (a zero volume
   *  counts as folded with severity 0), else 0; `folded` tells which. */
  double
  TetrahedronViolation(std::size_t t, const std::vector<Vec3> & points, bool & folded) const;

  /** The same for a tetrahedron given by its corners. */
  double
  TetrahedronViolation(std::size_t t, const Vec3 & a, const Vec3 & b, const Vec3 & c, const Vec3 & d,
                       bool & folded) const;
  /** All tetrahedra of one mesh; fills `perTetrahedron` when given. */
  FoldViolation
  Evaluate(const std::vector<Vec3> & points, std::vector<double> * perTetrahedron = nullptr) const;
  /** Both meshes of a solution. */
  FoldViolation
  Evaluate(const DualMesh & solution) const;

  /** Only the tetrahedra `touched` (e.g. a FOS element's dependent set) of one
   *  mesh: their violation summed. Evaluate(after) = Evaluate(before)
   *  - Partial(before, touched) + Partial(after, touched), exactly in the count. */
  FoldViolation
  Partial(const std::vector<Vec3> & points, const std::vector<std::uint32_t> & touched) const;

  /** Folded tetrahedra of one mesh, ascending. */
  std::vector<std::uint32_t>
  FoldedTetrahedra(const std::vector<Vec3> & points) const;

  const MeshTopology &
  Topology() const
  {
    return *m_Topology;
  }

private:
  const MeshTopology *     m_Topology;
  std::vector<std::int8_t> m_ReferenceSigns;
};
} // namespace morea

#endif

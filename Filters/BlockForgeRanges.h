/**
 * @file BlockForgeRanges.h
 * @brief Private helper: fills the value-range caches of output arrays, so that what
 * ParaView does after every update (its data information asks every array for the range
 * and the finite range of each component and of the vector norm; colour maps ask again)
 * reads cached values instead of scanning the arrays up to eight times.
 *
 * The caches are VTK's own (vtkAbstractArray::PER_COMPONENT, PER_FINITE_COMPONENT,
 * vtkDataArray::COMPONENT_RANGE, L2_NORM_RANGE, L2_NORM_FINITE_RANGE) and are dropped by
 * VTK whenever the array is modified, so a later change cannot leave a stale range.
 */
#pragma once

#include <vtkSmartPointer.h>

class vtkDataArray;
class vtkDoubleArray;
class vtkPoints;

namespace blockforge
{
namespace vtkglue
{
/// Computes every range in one pass over the values (on threads, see Core/Parallel.h)
/// and caches them. Call after the last change to the values.
void cacheRanges(vtkDoubleArray* array);

/**
 * Points on `coordinates` (3 components) whose bounds are already known: the ranges are
 * computed and cached as by cacheRanges(), in the same pass, and the bounds (the
 * per-component ranges, NaN skipped, as vtkPoints::ComputeBounds gives them) are set on
 * the points. ParaView's data information asks every grid for its bounds after an update;
 * vtkPoints would scan all coordinates again for them, on one core (about 0.7 s for 1e7
 * nodes). A later change of the coordinates drops the known bounds (they are recomputed).
 */
vtkSmartPointer<vtkPoints> pointsWithKnownBounds(vtkDoubleArray* coordinates);

/// Caches the ranges of an array whose values are all `value` (e.g. BlockId).
void cacheConstantRange(vtkDataArray* array, double value);
} // namespace vtkglue
} // namespace blockforge

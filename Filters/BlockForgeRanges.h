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

class vtkDataArray;
class vtkDoubleArray;

namespace blockforge
{
namespace vtkglue
{
/// Computes every range in one pass over the values (on threads, see Core/Parallel.h)
/// and caches them. Call after the last change to the values.
void cacheRanges(vtkDoubleArray* array);

/// Caches the ranges of an array whose values are all `value` (e.g. BlockId).
void cacheConstantRange(vtkDataArray* array, double value);
} // namespace vtkglue
} // namespace blockforge

#include "BlockForgeRanges.h"

#include "../Core/Parallel.h"

#include <vtkDoubleArray.h>
#include <vtkInformation.h>
#include <vtkInformationDoubleVectorKey.h>
#include <vtkInformationInformationVectorKey.h>
#include <vtkInformationVector.h>
#include <vtkNew.h>
#include <vtkObjectFactory.h>
#include <vtkPoints.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

namespace blockforge
{
namespace vtkglue
{
namespace
{
/// Ranges of one chunk of tuples: per component all (NaN skipped, as VTK does) and
/// finite values, and the squared norm of the tuples (finite ones).
struct Ranges
{
  explicit Ranges(int components)
    : all(2 * components)
    , finite(2 * components)
  {
    for (int c = 0; c < components; ++c)
    {
      all[2 * c] = finite[2 * c] = std::numeric_limits<double>::max();
      all[2 * c + 1] = finite[2 * c + 1] = std::numeric_limits<double>::lowest();
    }
  }
  std::vector<double> all, finite;
  double norm2[2] = { std::numeric_limits<double>::max(), std::numeric_limits<double>::lowest() };
  double finiteNorm2[2] = { std::numeric_limits<double>::max(),
    std::numeric_limits<double>::lowest() };

  void merge(const Ranges& other)
  {
    for (std::size_t n = 0; n < all.size(); n += 2)
    {
      all[n] = std::min(all[n], other.all[n]);
      all[n + 1] = std::max(all[n + 1], other.all[n + 1]);
      finite[n] = std::min(finite[n], other.finite[n]);
      finite[n + 1] = std::max(finite[n + 1], other.finite[n + 1]);
    }
    norm2[0] = std::min(norm2[0], other.norm2[0]);
    norm2[1] = std::max(norm2[1], other.norm2[1]);
    finiteNorm2[0] = std::min(finiteNorm2[0], other.finiteNorm2[0]);
    finiteNorm2[1] = std::max(finiteNorm2[1], other.finiteNorm2[1]);
  }
};

void setPerComponent(vtkInformation* info, vtkInformationInformationVectorKey* key,
  const std::vector<double>& ranges)
{
  const int components = static_cast<int>(ranges.size() / 2);
  vtkNew<vtkInformationVector> perComponent;
  perComponent->SetNumberOfInformationObjects(components);
  for (int c = 0; c < components; ++c)
  {
    perComponent->GetInformationObject(c)->Set(vtkDataArray::COMPONENT_RANGE(), &ranges[2 * c], 2);
  }
  info->Set(key, perComponent);
}

void store(vtkDataArray* array, const Ranges& ranges)
{
  vtkInformation* info = array->GetInformation();
  setPerComponent(info, vtkAbstractArray::PER_COMPONENT(), ranges.all);
  setPerComponent(info, vtkAbstractArray::PER_FINITE_COMPONENT(), ranges.finite);
  if (array->GetNumberOfComponents() > 1)
  {
    // VTK takes the root of the extreme squared norms, as here.
    const double norm[2] = { std::sqrt(ranges.norm2[0]), std::sqrt(ranges.norm2[1]) };
    const double finiteNorm[2] = { std::sqrt(ranges.finiteNorm2[0]),
      std::sqrt(ranges.finiteNorm2[1]) };
    info->Set(vtkDataArray::L2_NORM_RANGE(), norm, 2);
    info->Set(vtkDataArray::L2_NORM_FINITE_RANGE(), finiteNorm, 2);
  }
}
} // namespace

namespace
{
/// Computes (on threads) and caches every range of `array`; returns them.
Ranges computeAndCache(vtkDoubleArray* array)
{
  const vtkIdType tuples = array ? array->GetNumberOfTuples() : 0;
  if (tuples == 0)
  {
    return Ranges(array ? array->GetNumberOfComponents() : 0);
  }
  const int components = array->GetNumberOfComponents();
  const double* values = array->GetPointer(0);
  const long chunks = chunkCount(tuples, 1L << 16, 256);
  std::vector<Ranges> partial(static_cast<std::size_t>(chunks), Ranges(components));
  forEachChunk(chunks,
    [&](long chunk)
    {
      Ranges& ranges = partial[static_cast<std::size_t>(chunk)];
      const vtkIdType first = tuples * chunk / chunks;
      const vtkIdType last = tuples * (chunk + 1) / chunks;
      for (vtkIdType t = first; t < last; ++t)
      {
        const double* tuple = values + t * components;
        double norm2 = 0.0;
        for (int c = 0; c < components; ++c)
        {
          const double v = tuple[c];
          norm2 += v * v;
          if (!std::isnan(v))
          {
            ranges.all[2 * c] = std::min(ranges.all[2 * c], v);
            ranges.all[2 * c + 1] = std::max(ranges.all[2 * c + 1], v);
          }
          if (std::isfinite(v))
          {
            ranges.finite[2 * c] = std::min(ranges.finite[2 * c], v);
            ranges.finite[2 * c + 1] = std::max(ranges.finite[2 * c + 1], v);
          }
        }
        if (!std::isnan(norm2))
        {
          ranges.norm2[0] = std::min(ranges.norm2[0], norm2);
          ranges.norm2[1] = std::max(ranges.norm2[1], norm2);
        }
        if (std::isfinite(norm2))
        {
          ranges.finiteNorm2[0] = std::min(ranges.finiteNorm2[0], norm2);
          ranges.finiteNorm2[1] = std::max(ranges.finiteNorm2[1], norm2);
        }
      }
    });
  Ranges total(components);
  for (const Ranges& ranges : partial)
  {
    total.merge(ranges);
  }
  store(array, total);
  return total;
}

/// vtkPoints with bounds set from outside, kept until the points are modified.
class vtkPointsWithKnownBounds : public vtkPoints
{
public:
  static vtkPointsWithKnownBounds* New();
  vtkTypeMacro(vtkPointsWithKnownBounds, vtkPoints);
  void SetKnownBounds(const double bounds[6])
  {
    std::copy(bounds, bounds + 6, this->Bounds);
    this->ComputeTime.Modified(); // newer than the data: ComputeBounds keeps them
  }

protected:
  vtkPointsWithKnownBounds() = default;
  ~vtkPointsWithKnownBounds() override = default;
};
vtkStandardNewMacro(vtkPointsWithKnownBounds);
} // namespace

void cacheRanges(vtkDoubleArray* array)
{
  computeAndCache(array);
}

vtkSmartPointer<vtkPoints> pointsWithKnownBounds(vtkDoubleArray* coordinates)
{
  vtkNew<vtkPointsWithKnownBounds> points;
  points->SetData(coordinates);
  if (coordinates->GetNumberOfComponents() == 3 && coordinates->GetNumberOfTuples() > 0)
  {
    const Ranges ranges = computeAndCache(coordinates);
    points->SetKnownBounds(ranges.all.data());
  }
  return points.GetPointer();
}


void cacheConstantRange(vtkDataArray* array, double value)
{
  if (!array || array->GetNumberOfTuples() == 0)
  {
    return;
  }
  Ranges ranges(array->GetNumberOfComponents());
  for (std::size_t n = 0; n < ranges.all.size(); ++n)
  {
    ranges.all[n] = ranges.finite[n] = value;
  }
  const double norm2 = value * value * array->GetNumberOfComponents();
  ranges.norm2[0] = ranges.norm2[1] = ranges.finiteNorm2[0] = ranges.finiteNorm2[1] = norm2;
  store(array, ranges);
}
} // namespace vtkglue
} // namespace blockforge

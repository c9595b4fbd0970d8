#include "GridObjective.h"

#include "../../Core/InvertedCells.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace blockforge
{
namespace optimize
{
namespace
{
constexpr double radiansToDegrees = 57.295779513082320876798;
/// Edges shorter than this fraction of the block's extent take Core's collapsed-edge rules.
constexpr double collapsedFraction = 1.0e-12;
/// Beyond this many 1/sharpness above the minimum an exponential term is below 2e-9 of
/// the worst corner's: left out (most right angles drop out of the sum).
constexpr double softRange = 20.0;
/// Neighbour size ratios are capped here (a collapsed neighbour is not a ratio).
constexpr double ratioCap = 100.0;

inline std::size_t nodeIndex(int i, int j, int k, int ni, int nj)
{
  return static_cast<std::size_t>(i) +
    static_cast<std::size_t>(ni) * (static_cast<std::size_t>(j) + static_cast<std::size_t>(nj) * k);
}

/// Unit vectors and lengths of the grid edges of one direction: edge from node n to its
/// neighbour along `direction` stored at n (the last layer is unused).
struct EdgeField
{
  const double* unit = nullptr;
  const double* at(std::size_t node) const { return unit + 3 * node; }
};

inline double dot3(const double* a, const double* b)
{
  return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

/// The 4 corner cosines of the face spanned at `base` by directions a and b.
inline void faceCosines(const EdgeField& a, const EdgeField& b, std::size_t base,
  std::size_t stepA, std::size_t stepB, double* out)
{
  const double* a0 = a.at(base);
  const double* a1 = a.at(base + stepB);
  const double* b0 = b.at(base);
  const double* b1 = b.at(base + stepA);
  out[0] = dot3(a0, b0);
  out[1] = -dot3(a0, b1);
  out[2] = dot3(a1, b1);
  out[3] = -dot3(a1, b0);
}
} // namespace

const char* objectiveName(ObjectiveKind kind)
{
  switch (kind)
  {
    case ObjectiveKind::MinAngle:
      return "MinAngle";
    case ObjectiveKind::NonOrthogonality:
      return "NonOrthogonality";
    case ObjectiveKind::MinAngleAndSizeRatio:
      return "MinAngleAndSizeRatio";
  }
  return "MinAngle";
}

ObjectiveKind objectiveFromName(const std::string& name)
{
  for (ObjectiveKind kind : { ObjectiveKind::MinAngle, ObjectiveKind::NonOrthogonality,
         ObjectiveKind::MinAngleAndSizeRatio })
  {
    if (name == objectiveName(kind))
    {
      return kind;
    }
  }
  throw std::invalid_argument("unknown objective '" + name +
    "' (MinAngle, NonOrthogonality or MinAngleAndSizeRatio)");
}

BlockAngles::BlockAngles(const BlockGrid& grid)
  : Grid(grid)
{
  const int ni = grid.ni, nj = grid.nj, nk = grid.nk;
  if (ni < 2 || nj < 2 || nk < 2)
  {
    return;
  }
  const std::size_t nodes = static_cast<std::size_t>(ni) * nj * nk;
  Edges.assign(nodes * 12, 0.0); // 3 directions x (3 unit components + 1 length)
  Steps = { 1, static_cast<std::size_t>(ni), static_cast<std::size_t>(ni) * nj };
  const int counts[3] = { ni, nj, nk };
  Vec3 low = Vec3::Constant(1e300), high = Vec3::Constant(-1e300);
  for (std::size_t n = 0; n < nodes; ++n)
  {
    const Vec3 p(grid.xyz[3 * n], grid.xyz[3 * n + 1], grid.xyz[3 * n + 2]);
    low = low.cwiseMin(p);
    high = high.cwiseMax(p);
  }
  Collapsed = collapsedFraction * (high - low).norm();
  bool anyCollapsed = false;
  for (int d = 0; d < 3; ++d)
  {
    double* unit = Edges.data() + 3 * nodes * d;
    double* length = Edges.data() + 9 * nodes + nodes * d;
    for (int k = 0; k < nk; ++k)
    {
      for (int j = 0; j < nj; ++j)
      {
        for (int i = 0; i < ni; ++i)
        {
          const int index[3] = { i, j, k };
          if (index[d] + 1 >= counts[d])
          {
            continue;
          }
          const std::size_t n = nodeIndex(i, j, k, ni, nj);
          const double* p = grid.xyz + 3 * n;
          const double* q = grid.xyz + 3 * (n + Steps[d]);
          const double e[3] = { q[0] - p[0], q[1] - p[1], q[2] - p[2] };
          const double l = std::sqrt(e[0] * e[0] + e[1] * e[1] + e[2] * e[2]);
          length[n] = l;
          if (l <= Collapsed)
          {
            anyCollapsed = true;
            continue; // unit vector stays zero; the cell takes Core's rules
          }
          for (int c = 0; c < 3; ++c)
          {
            unit[3 * n + c] = e[c] / l;
          }
        }
      }
    }
  }
  const std::size_t cells = static_cast<std::size_t>(ni - 1) * (nj - 1) * (nk - 1);
  CellMin.resize(cells);
  Exact.assign(cells, 0);
  std::size_t cell = 0;
  for (int k = 0; k + 1 < nk; ++k)
  {
    for (int j = 0; j + 1 < nj; ++j)
    {
      for (int i = 0; i + 1 < ni; ++i, ++cell)
      {
        const std::size_t n = nodeIndex(i, j, k, ni, nj);
        if (anyCollapsed && touchesCollapsedEdge(n))
        {
          Exact[cell] = 1;
          CellMin[cell] = exactMinAngle(n);
          continue;
        }
        double cosines[24];
        cornerCosines(n, cosines);
        const double c = *std::max_element(cosines, cosines + 24);
        CellMin[cell] = std::acos(std::min(1.0, std::max(-1.0, c))) * radiansToDegrees;
      }
    }
  }
  for (double angle : CellMin)
  {
    Lowest = std::min(Lowest, angle);
  }
}

bool BlockAngles::touchesCollapsedEdge(std::size_t n) const
{
  const std::size_t nodes = Edges.size() / 12;
  for (int d = 0; d < 3; ++d)
  {
    const double* length = Edges.data() + 9 * nodes + nodes * d;
    const int a = (d + 1) % 3, b = (d + 2) % 3;
    for (std::size_t offset : { std::size_t(0), Steps[a], Steps[b], Steps[a] + Steps[b] })
    {
      if (length[n + offset] <= Collapsed)
      {
        return true;
      }
    }
  }
  return false;
}

double BlockAngles::exactMinAngle(std::size_t n) const
{
  std::array<Vec3, 8> corners;
  const std::size_t order[8] = { n, n + 1, n + 1 + Steps[1], n + Steps[1], n + Steps[2],
    n + 1 + Steps[2], n + 1 + Steps[1] + Steps[2], n + Steps[1] + Steps[2] };
  for (int c = 0; c < 8; ++c)
  {
    corners[c] =
      Vec3(Grid.xyz[3 * order[c]], Grid.xyz[3 * order[c] + 1], Grid.xyz[3 * order[c] + 2]);
  }
  double minAngle = 0.0, maxAngle = 0.0;
  hexFaceAngles(corners, minAngle, maxAngle);
  return minAngle;
}

void BlockAngles::cornerCosines(std::size_t n, double* out) const
{
  const std::size_t nodes = Edges.size() / 12;
  const EdgeField field[3] = { { Edges.data() }, { Edges.data() + 3 * nodes },
    { Edges.data() + 6 * nodes } };
  // Faces k0/k1 (i, j), j0/j1 (i, k), i0/i1 (j, k).
  faceCosines(field[0], field[1], n, Steps[0], Steps[1], out);
  faceCosines(field[0], field[1], n + Steps[2], Steps[0], Steps[1], out + 4);
  faceCosines(field[0], field[2], n, Steps[0], Steps[2], out + 8);
  faceCosines(field[0], field[2], n + Steps[1], Steps[0], Steps[2], out + 12);
  faceCosines(field[1], field[2], n, Steps[1], Steps[2], out + 16);
  faceCosines(field[1], field[2], n + Steps[0], Steps[1], Steps[2], out + 20);
}

double BlockAngles::cornerSum(double lowest, double sharpness) const
{
  const double cutoff = lowest + softRange / sharpness;
  const double cosineCutoff = std::cos(std::min(180.0, cutoff) / radiansToDegrees);
  double sum = 0.0;
  std::size_t cell = 0;
  const int ni = Grid.ni, nj = Grid.nj, nk = Grid.nk;
  for (int k = 0; k + 1 < nk; ++k)
  {
    for (int j = 0; j + 1 < nj; ++j)
    {
      for (int i = 0; i + 1 < ni; ++i, ++cell)
      {
        if (CellMin[cell] > cutoff)
        {
          continue;
        }
        if (Exact[cell])
        {
          sum += std::exp(-sharpness * (CellMin[cell] - lowest));
          continue;
        }
        double cosines[24];
        cornerCosines(nodeIndex(i, j, k, ni, nj), cosines);
        for (double c : cosines)
        {
          if (c >= cosineCutoff)
          {
            const double angle = std::acos(std::min(1.0, c)) * radiansToDegrees;
            sum += std::exp(-sharpness * (angle - lowest));
          }
        }
      }
    }
  }
  return sum;
}

void cellMinAngles(const BlockGrid& grid, double* out)
{
  const BlockAngles angles(grid);
  std::copy(angles.cellMinimum().begin(), angles.cellMinimum().end(), out);
}

double softMinimum(const std::vector<double>& values, double sharpness)
{
  if (values.empty())
  {
    return 0.0;
  }
  const double lowest = *std::min_element(values.begin(), values.end());
  const double cutoff = lowest + softRange / sharpness;
  double sum = 0.0;
  for (double value : values) // fixed order: the same sum bit for bit
  {
    if (value <= cutoff)
    {
      sum += std::exp(-sharpness * (value - lowest));
    }
  }
  return lowest - std::log(sum) / sharpness;
}

double maxNeighbourSizeRatio(const BlockGrid& grid)
{
  const int counts[3] = { grid.ni, grid.nj, grid.nk };
  const std::size_t steps[3] = { 1, static_cast<std::size_t>(grid.ni),
    static_cast<std::size_t>(grid.ni) * grid.nj };
  auto length = [&](std::size_t from, std::size_t to) {
    const double* p = grid.xyz + 3 * from;
    const double* q = grid.xyz + 3 * to;
    return std::sqrt((q[0] - p[0]) * (q[0] - p[0]) + (q[1] - p[1]) * (q[1] - p[1]) +
      (q[2] - p[2]) * (q[2] - p[2]));
  };
  double worst = 1.0;
  for (int d = 0; d < 3; ++d)
  {
    for (int k = 0; k < grid.nk; ++k)
    {
      for (int j = 0; j < grid.nj; ++j)
      {
        for (int i = 0; i < grid.ni; ++i)
        {
          const int index[3] = { i, j, k };
          if (index[d] + 2 >= counts[d])
          {
            continue;
          }
          const std::size_t n = nodeIndex(i, j, k, grid.ni, grid.nj);
          const double first = length(n, n + steps[d]);
          const double second = length(n + steps[d], n + 2 * steps[d]);
          const double small = std::min(first, second), large = std::max(first, second);
          if (small > 0.0)
          {
            worst = std::max(worst, std::min(ratioCap, large / small));
          }
        }
      }
    }
  }
  return worst;
}

double infeasibleObjective(long long invertedCells)
{
  return 1.0e4 + static_cast<double>(invertedCells);
}

GridMeasures measureAngles(const std::vector<const BlockAngles*>& blocks, double maxSizeRatio,
  const ObjectiveSettings& settings)
{
  GridMeasures measures;
  measures.feasible = true;
  std::vector<double> angles;
  for (const BlockAngles* block : blocks)
  {
    angles.insert(angles.end(), block->cellMinimum().begin(), block->cellMinimum().end());
  }
  measures.minAngle = angles.empty() ? 0.0 : *std::min_element(angles.begin(), angles.end());
  double sum = 0.0;
  // cornerSum leaves out the cells above this (as it computes it)
  const double cutoff = measures.minAngle + softRange / settings.angleSharpness;
  for (const BlockAngles* block : blocks) // block order: the same sum bit for bit
  {
    sum += block->cornerSum(measures.minAngle, settings.angleSharpness);
    measures.activeBlocks.push_back(block->lowest() <= cutoff ? 1 : 0);
  }
  measures.softMinAngle =
    sum > 0.0 ? measures.minAngle - std::log(sum) / settings.angleSharpness : measures.minAngle;
  measures.classes = minAngleClasses(angles.data(), angles.size());
  measures.objective = -measures.softMinAngle;
  if (settings.kind == ObjectiveKind::MinAngleAndSizeRatio)
  {
    measures.maxSizeRatio = maxSizeRatio;
    measures.objective +=
      settings.sizeRatioWeight * std::max(0.0, maxSizeRatio - settings.sizeRatioLimit);
  }
  return measures;
}

GridMeasures measureGrid(const std::vector<BlockGrid>& blocks,
  const std::vector<PeriodicSideLink>& periodic, const ObjectiveSettings& settings)
{
  GridMeasures measures;
  for (const BlockGrid& grid : blocks)
  {
    const InvertedCells inverted = findInvertedCells(grid.xyz, grid.ni, grid.nj, grid.nk);
    measures.invertedCells += inverted.count;
  }
  if (measures.invertedCells > 0)
  {
    measures.failure = std::to_string(measures.invertedCells) + " inverted cells";
    measures.objective = infeasibleObjective(measures.invertedCells);
    return measures;
  }
  std::vector<BlockAngles> fields;
  fields.reserve(blocks.size());
  std::vector<const BlockAngles*> pointers;
  double maxSizeRatio = 1.0;
  for (const BlockGrid& grid : blocks)
  {
    fields.emplace_back(grid);
    pointers.push_back(&fields.back());
    if (settings.kind == ObjectiveKind::MinAngleAndSizeRatio)
    {
      maxSizeRatio = std::max(maxSizeRatio, maxNeighbourSizeRatio(grid));
    }
  }
  measures = measureAngles(pointers, maxSizeRatio, settings);
  switch (settings.kind)
  {
    case ObjectiveKind::MinAngle:
    case ObjectiveKind::MinAngleAndSizeRatio:
      break;
    case ObjectiveKind::NonOrthogonality:
    {
      const std::vector<CellQualityArrays> quality = computeGridQuality(blocks, periodic);
      std::vector<double> negated;
      for (const CellQualityArrays& block : quality)
      {
        for (double value : block.nonOrthogonality)
        {
          measures.maxNonOrthogonality = std::max(measures.maxNonOrthogonality, value);
          negated.push_back(-value);
        }
      }
      // Smooth maximum as the negated smooth minimum of the negated values.
      measures.objective = -softMinimum(negated, settings.angleSharpness);
      break;
    }
  }
  return measures;
}

bool notWorse(const GridMeasures& candidate, const GridMeasures& reference, ObjectiveKind kind)
{
  if (!candidate.feasible)
  {
    return !reference.feasible && candidate.invertedCells <= reference.invertedCells;
  }
  if (!reference.feasible)
  {
    return true;
  }
  if (kind == ObjectiveKind::NonOrthogonality)
  {
    return candidate.maxNonOrthogonality <= reference.maxNonOrthogonality;
  }
  return candidate.minAngle >= reference.minAngle;
}
} // namespace optimize
} // namespace blockforge

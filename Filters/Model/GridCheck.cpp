#include "GridCheck.h"

#include "InvertedCells.h"
#include "ModelSyntax.h"
#include "Template.h"

#include <sstream>

namespace blockforge
{
namespace model
{
namespace
{
/// What is wrong with the block's cells, without the location; "" when nothing is.
std::string invertedCellText(const std::array<int, 3>& nodes, const InvertedCells& found)
{
  if (found.count == 0)
  {
    return {};
  }
  const std::int64_t cells = static_cast<std::int64_t>(nodes[0] - 1) * (nodes[1] - 1) *
    (nodes[2] - 1);
  std::ostringstream what;
  what << found.count << (found.count == 1 ? " inverted cell" : " inverted cells") << " of "
       << cells << " (" << nodes[0] - 1 << " x " << nodes[1] - 1 << " x " << nodes[2] - 1
       << " cells) in cell range";
  const char* axes = "ijk";
  for (int d = 0; d < 3; ++d)
  {
    what << (d ? ", " : " ") << axes[d] << " " << found.lowest[d];
    if (found.highest[d] != found.lowest[d])
    {
      what << "-" << found.highest[d];
    }
  }
  if (found.nonFinite > 0)
  {
    what << "; " << found.nonFinite << " of them with NaN or infinite nodes";
  }
  if (found.nonFinite < found.count)
  {
    what << "; worst scaled Jacobian " << syntax::shortNumber(found.worstScaledJacobian)
         << " at cell (" << found.worstCell[0] << ", " << found.worstCell[1] << ", "
         << found.worstCell[2] << ")";
  }
  what << "; the grid folds there: change the template's parameters, cell counts or "
          "density (or let the grid through for inspection: BlockMesher AllowInvertedCells)";
  return what.str();
}

TemplateError blockError(const BlockModel& model, int block, const std::string& what)
{
  const Block& b = model.blocks[block];
  return TemplateError(b.where.file, b.where.line, syntax::entity("block", b.name), what);
}
} // namespace

InvertedCellReport reportInvertedCells(
  const BlockModel& model, int block, const std::array<int, 3>& nodes, const double* xyz)
{
  const InvertedCells found = findInvertedCells(xyz, nodes[0], nodes[1], nodes[2]);
  InvertedCellReport report;
  report.cells = found.count;
  if (found.count > 0)
  {
    report.message = blockError(model, block, invertedCellText(nodes, found)).what();
  }
  return report;
}

void checkBlockCells(
  const BlockModel& model, int block, const std::array<int, 3>& nodes, const double* xyz)
{
  const InvertedCells found = findInvertedCells(xyz, nodes[0], nodes[1], nodes[2]);
  if (found.count > 0)
  {
    throw blockError(model, block, invertedCellText(nodes, found));
  }
}
} // namespace model
} // namespace blockforge

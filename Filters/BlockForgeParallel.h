/**
 * @file BlockForgeParallel.h
 * @brief Private glue for running BlockForge in parallel inside ParaView: threads through
 * vtkSMPTools for the numerical core, and the neighbour cells GridQuality needs from
 * other MPI ranks.
 */
#pragma once

#include "../Core/Quality.h"

#include <deque>
#include <string>
#include <vector>

class vtkDataObject;
class vtkMultiProcessController;

namespace blockforge
{
namespace vtkglue
{
/**
 * Lets the numerical core run its chunks of work (k-layers of large blocks when meshing
 * and measuring, value ranges) through vtkSMPTools. Debian's ParaView 5.11 builds the
 * Sequential and STDThread backends and starts on Sequential: unless the user chose one
 * (VTK_SMP_BACKEND_IN_USE), this switches the process to STDThread, which ParaView's own
 * threaded code (array ranges, many filters) then uses too. VTK_SMP_MAX_THREADS limits
 * the threads; VTK_SMP_BACKEND_IN_USE=Sequential keeps one. Idempotent. Results do not
 * depend on the threads, bit for bit.
 */
void useSMPTools();

/// What GridQuality measures its blocks with besides the blocks themselves.
struct QualityNeighbourhood
{
  /// Periodic links in the numbering of computeGridQuality with neighbours.
  std::vector<PeriodicSideLink> links;
  /// Cells of blocks on other MPI ranks beside interfaces and periodic faces.
  std::vector<NeighbourLayer> layers;
  /// Storage of the layers' nodes.
  std::deque<std::vector<double>> layerNodes;
  /// Periodic pairs of the model that do not fit the grid (changed after meshing).
  int unfit = 0;
  /// Under MPI without a block model the interfaces between ranks cannot be found.
  bool missingModel = false;
  /// Under MPI another rank failed before the exchange: this one must fail too (and not
  /// wait for it in later collective calls).
  bool peerFailed = false;
};

/**
 * The periodic links of the block model carried by `input` between the measured
 * `blocks` (named `names`, model blocks are found by name) and, when `controller` is
 * given (the pipeline runs in pieces on several ranks), the neighbour layers of the
 * blocks of other ranks across interfaces and periodic faces, exchanged with them.
 * Collective when `controller` is given: every rank calls it, also one that failed
 * (`ready` false: nothing is exchanged anywhere and the result is empty).
 */
QualityNeighbourhood findQualityNeighbours(vtkDataObject* input,
  const std::vector<std::string>& names, const std::vector<StructuredBlock>& blocks,
  vtkMultiProcessController* controller, bool ready = true);
} // namespace vtkglue
} // namespace blockforge

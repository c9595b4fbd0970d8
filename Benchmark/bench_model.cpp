/**
 * @file bench_model.cpp
 * @brief Google Benchmark program for the block model kept alive (issue 7): what one
 * evaluation costs after a control point moves, against building everything again.
 *
 * On Templates/axial_passage_oh.yaml with Data/rotor37/turbogrid (Rotor 37, 36 blades) at
 * the template's default density (10,848 cells since stop 13, 9,600 before):
 * - ApplyTemplate:      loadTemplate() with the point sets read once (what BlockTemplate
 *                       does per update), the carriers handed over;
 * - FullEvaluation:     MultiBlockMesher (full model check) + computeBoundaries() +
 *                       meshBlock() of every block + computeGridQuality() of the grid:
 *                       what an evaluation cost before the mesh plan;
 * - MoveOneControlPoint: one evaluation with a MeshPlan built once: the O-grid corner
 *                       oa_f_h moved along its carrier (moveParameter: placement of it and
 *                       of what follows it: a_f_h projected from it, the mid-passage and
 *                       inlet vertices placed by expressions of it, the periodic line
 *                       drawn through them), update() (dependent edges, faces, checks, TFI
 *                       of the affected blocks) and MinAngle of the affected cells;
 * - MoveOneControlPointAndUndo: the same, then MeshPlan::undo() (an optimizer's rejected
 *                       trial move: the move and putting everything back, instead of a
 *                       second update moving it back);
 * - MoveOneControlPointWithoutChains: the same on the model without expression and curve
 *                       chains (only a_f_h follows, as before they were kept): the same
 *                       work as before, for comparison with older builds.
 * Run with repetitions and read the medians:
 *   bench_model --benchmark_repetitions=7 --benchmark_report_aggregates_only=true
 * `--threads=N` (first argument) runs the numerical core's chunks of work on N threads
 * of a pool (Core/Parallel.h; ParaView installs vtkSMPTools' in the same way): the
 * grids are the same bits, the wall-clock times (Time column) show the gain; the CPU
 * column is the whole process's, all threads added up.
 */
#include <benchmark/benchmark.h>

#include "Mesher.h"
#include "Quality.h"
#include "Template.h"
#include "TestTurboInputs.h"
#if __has_include("MeshPlan.h")
#include "MeshPlan.h"
#include "Placement.h"
#define BLOCKFORGE_HAS_MESH_PLAN 1
#endif

#include "Parallel.h"

#include <algorithm>
#include <array>
#include <memory>
#include <atomic>
#include <cmath>
#include <condition_variable>
#include <cstdlib>
#include <cstring>
#include <functional>
#include <iostream>
#include <mutex>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#ifndef BLOCKFORGE_SOURCE_DIR
#define BLOCKFORGE_SOURCE_DIR "."
#endif

namespace
{
using namespace blockforge;

const std::string Source = BLOCKFORGE_SOURCE_DIR;

/**
 * A pool of threads kept for the whole run (starting threads for every chunked loop
 * would cost more than the small loops of one evaluation): the caller and the workers
 * take chunks in turn, and the caller waits only for chunks a worker has taken, never
 * for a worker to wake up (on a loaded machine that can take a time slice). A loop
 * started from inside a chunk runs in the thread that started it, as vtkSMPTools runs
 * nested loops.
 */
class ThreadPool
{
public:
  explicit ThreadPool(int threads)
  {
    for (int t = 1; t < threads; ++t)
    {
      Workers.emplace_back([this] { work(); });
    }
  }
  ~ThreadPool()
  {
    {
      std::lock_guard<std::mutex> lock(Mutex);
      Stop = true;
    }
    Wake.notify_all();
    for (std::thread& worker : Workers)
    {
      worker.join();
    }
  }
  ThreadPool(const ThreadPool&) = delete;
  ThreadPool& operator=(const ThreadPool&) = delete;

  void run(long count, const std::function<void(long, long)>& body)
  {
    if (InChunk || Workers.empty() || count <= 1)
    {
      body(0, count);
      return;
    }
    const auto job = std::make_shared<Job>();
    job->body = &body;
    job->count = count;
    {
      std::lock_guard<std::mutex> lock(Mutex);
      Current = job;
      ++Generation;
    }
    Wake.notify_all();
    drain(*job);
    std::unique_lock<std::mutex> lock(Mutex);
    Done.wait(lock, [&] { return job->finished.load() == job->count; });
  }

private:
  /// One loop: chunks are taken by counting up `next`; a worker that wakes after all
  /// are taken finds none (the job outlives the loop while a worker holds it).
  struct Job
  {
    const std::function<void(long, long)>* body = nullptr;
    long count = 0;
    std::atomic<long> next{ 0 };
    std::atomic<long> finished{ 0 };
  };

  void drain(Job& job)
  {
    InChunk = true;
    for (long chunk = job.next++; chunk < job.count; chunk = job.next++)
    {
      (*job.body)(chunk, chunk + 1);
      if (++job.finished == job.count)
      {
        std::lock_guard<std::mutex> lock(Mutex);
        Done.notify_all();
      }
    }
    InChunk = false;
  }
  void work()
  {
    unsigned long seen = 0;
    for (;;)
    {
      std::shared_ptr<Job> job;
      {
        std::unique_lock<std::mutex> lock(Mutex);
        Wake.wait(lock, [&] { return Stop || Generation != seen; });
        if (Stop)
        {
          return;
        }
        seen = Generation;
        job = Current;
      }
      drain(*job);
    }
  }

  static thread_local bool InChunk;
  std::vector<std::thread> Workers;
  std::mutex Mutex;
  std::condition_variable Wake, Done;
  std::shared_ptr<Job> Current;
  unsigned long Generation = 0;
  bool Stop = false;
};
thread_local bool ThreadPool::InChunk = false;

/// The reader's point sets as vtkBlockTemplate hands them to the template (metres).
const model::TemplateInputs& rotor37Inputs()
{
  static const model::TemplateInputs inputs =
    test::readTemplateInputs(Source + "/Data/rotor37/turbogrid/BladeGen.inf");
  return inputs;
}

/// Templates/axial_passage_oh.yaml, or the template named by BLOCKFORGE_BENCH_TEMPLATE
/// (an older revision of it, to compare what a template change costs).
const std::string& templatePath()
{
  static const std::string path = [] {
    const char* chosen = std::getenv("BLOCKFORGE_BENCH_TEMPLATE");
    return chosen && *chosen ? std::string(chosen) : Source + "/Templates/axial_passage_oh.yaml";
  }();
  return path;
}

struct Applied
{
  model::BlockModel model;
  model::CarrierGeometry carriers;
};

const Applied& applied()
{
  static const Applied result = [] {
    Applied a;
    a.model = model::loadTemplate(templatePath(), {}, &rotor37Inputs(), &a.carriers);
    return a;
  }();
  return result;
}

void BM_ApplyTemplate(benchmark::State& state)
{
  const model::TemplateInputs& inputs = rotor37Inputs();
  for (auto _ : state)
  {
    model::CarrierGeometry carriers;
    model::BlockModel model = model::loadTemplate(templatePath(), {}, &inputs, &carriers);
    benchmark::DoNotOptimize(model.vertices.data());
  }
}

void BM_FullEvaluation(benchmark::State& state)
{
  const Applied& a = applied();
  std::vector<std::vector<double>> xyz;
  long long cells = 0;
  for (auto _ : state)
  {
    model::MultiBlockMesher mesher(a.model, a.carriers);
    mesher.computeBoundaries();
    xyz.resize(mesher.blockCount());
    std::vector<StructuredBlock> blocks;
    cells = 0;
    for (int b = 0; b < mesher.blockCount(); ++b)
    {
      const auto n = mesher.nodeCounts(b);
      xyz[b].resize(3 * static_cast<std::size_t>(n[0]) * n[1] * n[2]);
      mesher.meshBlock(b, xyz[b].data());
      blocks.push_back({ xyz[b].data(), n[0], n[1], n[2] });
      cells += static_cast<long long>(n[0] - 1) * (n[1] - 1) * (n[2] - 1);
    }
    const auto quality = computeGridQuality(blocks);
    benchmark::DoNotOptimize(quality.data());
  }
  state.counters["cells"] = static_cast<double>(cells);
}

#ifdef BLOCKFORGE_HAS_MESH_PLAN
/// Smallest MinAngle of the cells of block b (Quality.h: the smallest hexFaceAngles
/// minAngle of its cells, bit for bit).
double smallestMinAngleOf(const std::vector<double>& xyz, const std::array<int, 3>& n, long long& cells)
{
  cells += static_cast<long long>(n[0] - 1) * (n[1] - 1) * (n[2] - 1);
  return smallestMinAngle(xyz.data(), n[0], n[1], n[2]);
}

/// The model without what follows through expressions and curves (as before issue 7's
/// chains): the same move then updates what it updated before, for comparison.
const Applied& appliedWithoutChains()
{
  static const Applied result = [] {
    Applied a = applied();
    for (model::Vertex& vertex : a.model.vertices)
    {
      vertex.rule.expressions = model::PlacementExpressions();
    }
    for (model::Carrier& carrier : a.model.carriers)
    {
      carrier.throughVertices.clear();
    }
    for (model::Edge& edge : a.model.edges)
    {
      edge.atExpressions.clear();
      edge.atFollows.clear();
    }
    return a;
  }();
  return result;
}

/**
 * The control point the entries move: the O-grid corner `oa_f_h` when the template has
 * one (the figures of earlier builds), else the vertex with a free parameter that most
 * vertices follow (the template is redesigned from time to time; the entry must keep
 * measuring a move with followers).
 */
model::FreeParameter movedParameter(const model::BlockModel& model, const model::CarrierGeometry& carriers)
{
  const std::vector<model::FreeParameter> parameters = model::freeParameters(model, carriers);
  const std::vector<std::vector<int>> dependents = model::vertexDependents(model);
  const int corner = model.findVertex("oa_f_h");
  const model::FreeParameter* best = nullptr;
  for (const model::FreeParameter& p : parameters)
  {
    if (p.component != 0)
    {
      continue;
    }
    if (p.vertex == corner)
    {
      return p;
    }
    if (!best || dependents[p.vertex].size() > dependents[best->vertex].size())
    {
      best = &p;
    }
  }
  if (!best)
  {
    throw std::runtime_error("the template has no vertex with a free parameter to move");
  }
  return *best;
}

void moveOneControlPoint(benchmark::State& state, const Applied& a, bool undo = false)
{
  model::MeshPlan plan(a.model, a.carriers);
  const model::FreeParameter parameter = movedParameter(plan.model(), plan.carriers());
  const int vertex = parameter.vertex;
  const double original = plan.model().vertices[vertex].constraint.s;
  long long step = 0, cells = 0, blocks = 0, infeasible = 0;
  for (auto _ : state)
  {
    // Along the O-grid curve by up to 0.003 either way, never to the same place twice
    // (nothing is served from what an earlier iteration computed at the same position).
    const double offset = 0.003 * std::sin(0.7 * static_cast<double>(++step));
    const std::vector<int> moved =
      model::moveParameter(plan.model(), plan.carriers(), parameter, original + offset);
    const model::Feasibility feasibility = plan.update(moved);
    infeasible += feasibility.feasible() ? 0 : 1;
    const std::vector<int>& updated = plan.updatedBlocks();
    std::vector<double> smallestOf(updated.size(), 180.0);
    std::vector<long long> cellsOf(updated.size(), 0);
    forEachChunk(static_cast<long>(updated.size()), [&](long n) {
      smallestOf[n] = smallestMinAngleOf(plan.blockNodes(updated[n]), plan.nodeCounts(updated[n]), cellsOf[n]);
    });
    double smallest = 180.0;
    cells = 0;
    for (std::size_t n = 0; n < updated.size(); ++n)
    {
      smallest = std::min(smallest, smallestOf[n]);
      cells += cellsOf[n];
    }
    blocks = static_cast<long long>(plan.updatedBlocks().size());
    benchmark::DoNotOptimize(smallest);
    if (undo && !plan.undo())
    {
      state.SkipWithError("MeshPlan::undo found nothing to undo");
    }
  }
  state.counters["blocks"] = static_cast<double>(blocks);
  state.counters["cells"] = static_cast<double>(cells);
  state.counters["infeasible"] = static_cast<double>(infeasible);
}

void BM_MoveOneControlPoint(benchmark::State& state)
{
  moveOneControlPoint(state, applied());
}

void BM_MoveOneControlPointWithoutChains(benchmark::State& state)
{
  moveOneControlPoint(state, appliedWithoutChains());
}

void BM_MoveOneControlPointAndUndo(benchmark::State& state)
{
  moveOneControlPoint(state, applied(), true);
}
#endif
} // namespace

int main(int argc, char** argv)
{
  int threads = 1;
  if (argc > 1 && std::strncmp(argv[1], "--threads=", 10) == 0)
  {
    threads = std::max(1, std::atoi(argv[1] + 10));
    for (int a = 1; a + 1 < argc; ++a)
    {
      argv[a] = argv[a + 1];
    }
    --argc;
  }
  std::unique_ptr<ThreadPool> pool;
  if (threads > 1)
  {
    pool.reset(new ThreadPool(threads));
    ThreadPool* runner = pool.get();
    setChunkRunner(
      [runner](long count, const std::function<void(long, long)>& body) { runner->run(count, body); },
      threads);
  }
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv))
  {
    return 1;
  }
  try
  {
    benchmark::AddCustomContext("template", templatePath());
    benchmark::AddCustomContext("threads", std::to_string(threads));
    benchmark::AddCustomContext("moved vertex",
      applied().model.vertices[movedParameter(applied().model, applied().carriers).vertex].name);
    benchmark::AddCustomContext("blocks", std::to_string(applied().model.blocks.size()));
  }
  catch (const std::exception& error)
  {
    std::cerr << "bench_model: " << error.what() << "\n";
    return 1;
  }
  benchmark::RegisterBenchmark("ApplyTemplate", BM_ApplyTemplate)
    ->MeasureProcessCPUTime()
    ->UseRealTime()
    ->Unit(benchmark::kMillisecond);
  benchmark::RegisterBenchmark("FullEvaluation", BM_FullEvaluation)
    ->MeasureProcessCPUTime()
    ->UseRealTime()
    ->Unit(benchmark::kMillisecond);
#ifdef BLOCKFORGE_HAS_MESH_PLAN
  benchmark::RegisterBenchmark("MoveOneControlPoint", BM_MoveOneControlPoint)
    ->MeasureProcessCPUTime()
    ->UseRealTime()
    ->Unit(benchmark::kMillisecond);
  benchmark::RegisterBenchmark("MoveOneControlPointAndUndo", BM_MoveOneControlPointAndUndo)
    ->MeasureProcessCPUTime()
    ->UseRealTime()
    ->Unit(benchmark::kMillisecond);
  benchmark::RegisterBenchmark("MoveOneControlPointWithoutChains", BM_MoveOneControlPointWithoutChains)
    ->MeasureProcessCPUTime()
    ->UseRealTime()
    ->Unit(benchmark::kMillisecond);
#endif
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  setChunkRunner({}, 1);
  return 0;
}

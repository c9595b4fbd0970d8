/**
 * @file bench_core.cpp
 * @brief Google Benchmark program for the numerical core, one core, in memory.
 *
 * On the cylinder_in_box template (4-block O-grid) at density multipliers giving about
 * 1e5, 1e6 and 1e7 nodes (nodes counted per block, shared faces in each block):
 * - Mesher/<size>:      MultiBlockMesher construction (model check) + computeBoundaries()
 *                       + meshBlock() of every block into preallocated buffers [nodes/s];
 * - MeshBlocks/<size>:  meshBlock() of every block only (boundaries computed once);
 * - Quality/<size>:     computeGridQuality() of the grid (all seven measures) [cells/s];
 * - CheckCells/<size>:  findInvertedCells() of every block, the mesher's check of every
 *                       grid it hands out, to compare with MeshBlocks [cells/s];
 * and, as the limit to approach, on a unit cube with the same node count:
 * - PlainTFI/<size>:    a plain trilinear TFI loop (paper eq. 6 evaluated node by node
 *                       from the 6 faces, 12 edges, 8 vertices) [nodes/s];
 * - TransfiniteBlock/<size>: blockforge::transfiniteBlock() on that cube [nodes/s].
 *
 * Run with repetitions and look at the medians, for instance
 *   bench_core --benchmark_repetitions=5 --benchmark_report_aggregates_only=true
 * The template is Templates/cylinder_in_box.yaml of the source tree, or the file named by
 * the environment variable BLOCKFORGE_BENCH_TEMPLATE.
 */
#include <benchmark/benchmark.h>

#include "InvertedCells.h"
#include "Mesher.h"
#include "Quality.h"
#include "Template.h"
#include "Transfinite.h"

#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <iostream>
#include <memory>
#include <string>
#include <vector>

#ifndef BLOCKFORGE_SOURCE_DIR
#define BLOCKFORGE_SOURCE_DIR "."
#endif

namespace
{
using namespace blockforge;

std::string templatePath()
{
  if (const char* path = std::getenv("BLOCKFORGE_BENCH_TEMPLATE"))
  {
    if (*path)
    {
      return path;
    }
  }
  return std::string(BLOCKFORGE_SOURCE_DIR) + "/Templates/cylinder_in_box.yaml";
}

const model::BlockModel& cylinderModel()
{
  static const model::BlockModel model = model::loadTemplate(templatePath());
  return model;
}

struct Counts
{
  long long nodes = 0;
  long long cells = 0;
};

Counts gridCounts(const model::BlockModel& model, double multiplier)
{
  model::MultiBlockMesher mesher(model, multiplier);
  Counts counts;
  for (int b = 0; b < mesher.blockCount(); ++b)
  {
    const auto n = mesher.nodeCounts(b);
    counts.nodes += static_cast<long long>(n[0]) * n[1] * n[2];
    counts.cells += static_cast<long long>(n[0] - 1) * (n[1] - 1) * (n[2] - 1);
  }
  return counts;
}

/// The density multiplier whose node count is closest to `target` (counts are monotone
/// in the multiplier, with steps from the rounding of the cell counts).
double multiplierFor(const model::BlockModel& model, double target)
{
  double low = 0.01, high = 100.0;
  for (int step = 0; step < 60; ++step)
  {
    const double middle = std::sqrt(low * high);
    if (static_cast<double>(gridCounts(model, middle).nodes) < target)
    {
      low = middle;
    }
    else
    {
      high = middle;
    }
  }
  const double below = static_cast<double>(gridCounts(model, low).nodes);
  const double above = static_cast<double>(gridCounts(model, high).nodes);
  return std::abs(std::log(below / target)) <= std::abs(std::log(above / target)) ? low : high;
}

/// A meshed grid, kept between the benchmarks of one size (one size at a time).
struct Grid
{
  double multiplier = 0.0;
  Counts counts;
  std::vector<std::array<int, 3>> dims;
  std::vector<std::vector<double>> xyz;
};

Grid& meshedGrid(double multiplier)
{
  static std::unique_ptr<Grid> grid;
  if (!grid || grid->multiplier != multiplier)
  {
    grid.reset(); // free the previous size first
    auto fresh = std::make_unique<Grid>();
    fresh->multiplier = multiplier;
    model::MultiBlockMesher mesher(cylinderModel(), multiplier);
    mesher.computeBoundaries();
    for (int b = 0; b < mesher.blockCount(); ++b)
    {
      const auto n = mesher.nodeCounts(b);
      fresh->dims.push_back(n);
      fresh->xyz.emplace_back(3 * static_cast<size_t>(n[0]) * n[1] * n[2]);
      mesher.meshBlock(b, fresh->xyz.back().data());
      fresh->counts.nodes += static_cast<long long>(n[0]) * n[1] * n[2];
      fresh->counts.cells += static_cast<long long>(n[0] - 1) * (n[1] - 1) * (n[2] - 1);
    }
    grid = std::move(fresh);
  }
  return *grid;
}

void setRates(benchmark::State& state, const char* name, long long count)
{
  state.counters[name] =
    benchmark::Counter(static_cast<double>(count), benchmark::Counter::kIsIterationInvariantRate);
}

void BM_Mesher(benchmark::State& state, double multiplier)
{
  Grid& grid = meshedGrid(multiplier); // buffers allocated and touched
  const model::BlockModel& model = cylinderModel();
  for (auto _ : state)
  {
    model::MultiBlockMesher mesher(model, multiplier);
    mesher.computeBoundaries();
    for (int b = 0; b < mesher.blockCount(); ++b)
    {
      mesher.meshBlock(b, grid.xyz[b].data());
    }
    benchmark::ClobberMemory();
  }
  setRates(state, "nodes/s", grid.counts.nodes);
  state.counters["nodes"] = static_cast<double>(grid.counts.nodes);
  state.counters["multiplier"] = multiplier;
}

void BM_MeshBlocks(benchmark::State& state, double multiplier)
{
  Grid& grid = meshedGrid(multiplier);
  model::MultiBlockMesher mesher(cylinderModel(), multiplier);
  mesher.computeBoundaries();
  for (auto _ : state)
  {
    for (int b = 0; b < mesher.blockCount(); ++b)
    {
      mesher.meshBlock(b, grid.xyz[b].data());
    }
    benchmark::ClobberMemory();
  }
  setRates(state, "nodes/s", grid.counts.nodes);
  state.counters["nodes"] = static_cast<double>(grid.counts.nodes);
}

void BM_Quality(benchmark::State& state, double multiplier)
{
  Grid& grid = meshedGrid(multiplier);
  std::vector<StructuredBlock> blocks;
  for (size_t b = 0; b < grid.xyz.size(); ++b)
  {
    StructuredBlock block;
    block.xyz = grid.xyz[b].data();
    block.ni = grid.dims[b][0];
    block.nj = grid.dims[b][1];
    block.nk = grid.dims[b][2];
    blocks.push_back(block);
  }
  for (auto _ : state)
  {
    std::vector<CellQualityArrays> quality = computeGridQuality(blocks);
    benchmark::DoNotOptimize(quality.data());
    benchmark::ClobberMemory();
  }
  setRates(state, "cells/s", grid.counts.cells);
  state.counters["cells"] = static_cast<double>(grid.counts.cells);
}

void BM_CheckCells(benchmark::State& state, double multiplier)
{
  Grid& grid = meshedGrid(multiplier);
  for (auto _ : state)
  {
    std::int64_t inverted = 0;
    for (size_t b = 0; b < grid.xyz.size(); ++b)
    {
      inverted += findInvertedCells(
        grid.xyz[b].data(), grid.dims[b][0], grid.dims[b][1], grid.dims[b][2])
                    .count;
    }
    benchmark::DoNotOptimize(inverted);
  }
  setRates(state, "cells/s", grid.counts.cells);
  state.counters["cells"] = static_cast<double>(grid.counts.cells);
}

/// Unit cube with n^3 nodes, uniform parameters, faces in Transfinite.h conventions.
struct Cube
{
  int n = 0;
  std::vector<double> params;
  std::array<std::vector<double>, 6> faces;
  std::vector<double> out;

  explicit Cube(int count)
    : n(count)
  {
    params.resize(n);
    for (int i = 0; i < n; ++i)
    {
      params[i] = static_cast<double>(i) / (n - 1);
    }
    params[n - 1] = 1.0;
    for (auto& face : faces)
    {
      face.resize(3 * static_cast<size_t>(n) * n);
    }
    for (int b = 0; b < n; ++b)
    {
      for (int a = 0; a < n; ++a)
      {
        const double p = params[a], q = params[b];
        const size_t at = 3 * (a + static_cast<size_t>(n) * b);
        const double values[6][3] = {
          { 0, p, q }, { 1, p, q }, // s = 0, 1: (j, k)
          { p, 0, q }, { p, 1, q }, // t = 0, 1: (i, k)
          { p, q, 0 }, { p, q, 1 }  // u = 0, 1: (i, j)
        };
        for (int f = 0; f < 6; ++f)
        {
          for (int c = 0; c < 3; ++c)
          {
            faces[f][at + c] = values[f][c];
          }
        }
      }
    }
    out.assign(3 * static_cast<size_t>(n) * n * n, 0.0);
  }
  long long nodes() const { return static_cast<long long>(n) * n * n; }
};

/// The plain loop: paper eq. 6 at every node, faces - edges + vertices.
void plainTransfinite(const Cube& cube, double* out)
{
  const int n = cube.n;
  const double* p = cube.params.data();
  auto at = [n](const std::vector<double>& face, int a, int b) {
    return face.data() + 3 * (a + static_cast<long>(n) * b);
  };
  const auto& S0 = cube.faces[0];
  const auto& S1 = cube.faces[1];
  const auto& T0 = cube.faces[2];
  const auto& T1 = cube.faces[3];
  const auto& U0 = cube.faces[4];
  const auto& U1 = cube.faces[5];
  const int m = n - 1;
  const double* V[8] = { at(U0, 0, 0), at(U0, m, 0), at(U0, m, m), at(U0, 0, m), at(U1, 0, 0),
    at(U1, m, 0), at(U1, m, m), at(U1, 0, m) };
  for (int k = 0; k < n; ++k)
  {
    const double u = p[k], u1 = 1.0 - u;
    for (int j = 0; j < n; ++j)
    {
      const double t = p[j], t1 = 1.0 - t;
      double* row = out + 3 * (static_cast<long>(n) * n * k + static_cast<long>(n) * j);
      for (int i = 0; i < n; ++i)
      {
        const double s = p[i], s1 = 1.0 - s;
        const double *s0 = at(S0, j, k), *s1f = at(S1, j, k), *t0 = at(T0, i, k),
                     *t1f = at(T1, i, k), *u0 = at(U0, i, j), *u1f = at(U1, i, j);
        const double *e0 = at(U0, i, 0), *e2 = at(U0, i, m), *e4 = at(U1, i, 0),
                     *e6 = at(U1, i, m), *e3 = at(U0, 0, j), *e1 = at(U0, m, j),
                     *e7 = at(U1, 0, j), *e5 = at(U1, m, j), *e8 = at(T0, 0, k),
                     *e9 = at(T0, m, k), *e11 = at(T1, 0, k), *e10 = at(T1, m, k);
        for (int c = 0; c < 3; ++c)
        {
          const double faces =
            s1 * s0[c] + s * s1f[c] + t1 * t0[c] + t * t1f[c] + u1 * u0[c] + u * u1f[c];
          const double edges = t1 * u1 * e0[c] + t * u1 * e2[c] + t1 * u * e4[c] +
            t * u * e6[c] + s1 * u1 * e3[c] + s * u1 * e1[c] + s1 * u * e7[c] + s * u * e5[c] +
            s1 * t1 * e8[c] + s * t1 * e9[c] + s1 * t * e11[c] + s * t * e10[c];
          const double vertices = s1 * t1 * u1 * V[0][c] + s * t1 * u1 * V[1][c] +
            s * t * u1 * V[2][c] + s1 * t * u1 * V[3][c] + s1 * t1 * u * V[4][c] +
            s * t1 * u * V[5][c] + s * t * u * V[6][c] + s1 * t * u * V[7][c];
          row[3 * i + c] = faces - edges + vertices;
        }
      }
    }
  }
}

std::unique_ptr<Cube>& cubeCache()
{
  static std::unique_ptr<Cube> cube;
  return cube;
}

Cube& cubeWithNodes(long long nodes)
{
  const int n = std::max(3, static_cast<int>(std::lround(std::cbrt(static_cast<double>(nodes)))));
  auto& cube = cubeCache();
  if (!cube || cube->n != n)
  {
    cube.reset();
    cube = std::make_unique<Cube>(n);
  }
  return *cube;
}

void BM_PlainTFI(benchmark::State& state, long long nodes)
{
  Cube& cube = cubeWithNodes(nodes);
  for (auto _ : state)
  {
    plainTransfinite(cube, cube.out.data());
    benchmark::ClobberMemory();
  }
  setRates(state, "nodes/s", cube.nodes());
  state.counters["nodes"] = static_cast<double>(cube.nodes());
}

void BM_TransfiniteBlock(benchmark::State& state, long long nodes)
{
  Cube& cube = cubeWithNodes(nodes);
  BlockBoundary boundary;
  for (int f = 0; f < 6; ++f)
  {
    boundary.faces[f] = cube.faces[f].data();
  }
  for (int e = 0; e < 12; ++e)
  {
    boundary.edgeParams[e] = cube.params.data();
  }
  for (auto _ : state)
  {
    transfiniteBlock(boundary, cube.n, cube.n, cube.n, cube.out.data());
    benchmark::ClobberMemory();
  }
  setRates(state, "nodes/s", cube.nodes());
  state.counters["nodes"] = static_cast<double>(cube.nodes());
}
} // namespace

int main(int argc, char** argv)
{
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv))
  {
    return 1;
  }
  struct Size
  {
    const char* label;
    double target;
  };
  const Size sizes[] = { { "1e5", 1e5 }, { "1e6", 1e6 }, { "1e7", 1e7 } };
  const std::string path = templatePath();
  try
  {
    const model::BlockModel& model = cylinderModel();
    benchmark::AddCustomContext("template", path);
    for (const Size& size : sizes)
    {
      const double multiplier = multiplierFor(model, size.target);
      const Counts counts = gridCounts(model, multiplier);
      char text[160];
      std::snprintf(text, sizeof(text), "density multiplier %.6g: %lld nodes, %lld cells",
        multiplier, counts.nodes, counts.cells);
      benchmark::AddCustomContext(std::string("size ") + size.label, text);
      const std::string suffix = std::string("/") + size.label;
      benchmark::RegisterBenchmark(("Mesher" + suffix).c_str(), BM_Mesher, multiplier)
        ->UseRealTime()
        ->Unit(benchmark::kMillisecond);
      benchmark::RegisterBenchmark(("MeshBlocks" + suffix).c_str(), BM_MeshBlocks, multiplier)
        ->UseRealTime()
        ->Unit(benchmark::kMillisecond);
      benchmark::RegisterBenchmark(("Quality" + suffix).c_str(), BM_Quality, multiplier)
        ->UseRealTime()
        ->Unit(benchmark::kMillisecond);
      benchmark::RegisterBenchmark(("CheckCells" + suffix).c_str(), BM_CheckCells, multiplier)
        ->UseRealTime()
        ->Unit(benchmark::kMillisecond);
      benchmark::RegisterBenchmark(("PlainTFI" + suffix).c_str(), BM_PlainTFI, counts.nodes)
        ->UseRealTime()
        ->Unit(benchmark::kMillisecond);
      benchmark::RegisterBenchmark(
        ("TransfiniteBlock" + suffix).c_str(), BM_TransfiniteBlock, counts.nodes)
        ->UseRealTime()
        ->Unit(benchmark::kMillisecond);
    }
  }
  catch (const std::exception& error)
  {
    std::cerr << "bench_core: " << path << ": " << error.what() << "\n";
    return 1;
  }
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}

/**
 * @file TestHelpers.h
 * @brief Small helpers shared by the C++ tests of the model and the template engine.
 * Header-only; for tests that link BlockForgeModel.
 */
#pragma once

#include "Mesher.h"
#include "Template.h"

#include "Parallel.h"

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstddef>
#include <cstring>
#include <fstream>
#include <functional>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

namespace blockforge
{
namespace test
{
constexpr double Pi = 3.14159265358979323846;

/// A file of the source tree, e.g. sourcePath("Templates/cylinder_in_box.yaml").
inline std::string sourcePath(const std::string& relative)
{
  return std::string(BLOCKFORGE_SOURCE_DIR) + "/" + relative;
}

/// A template of Templates/, by file name.
inline std::string templatePath(const std::string& fileName)
{
  return sourcePath("Templates/" + fileName);
}

/// The parameter-only example templates.
inline const std::vector<std::string>& exampleTemplates()
{
  static const std::vector<std::string> names = { "cylinder_in_box.yaml",
    "annular_sector.yaml", "wedge_sector.yaml" };
  return names;
}

/// 1-based number of the first line of `text` containing `needle` (a test failure if none).
inline int lineContaining(const std::string& text, const std::string& needle)
{
  std::istringstream stream(text);
  int number = 0;
  for (std::string line; std::getline(stream, line);)
  {
    ++number;
    if (line.find(needle) != std::string::npos)
    {
      return number;
    }
  }
  ADD_FAILURE() << "no line contains " << needle;
  return 0;
}

/// The whole content of a text file ("" if it cannot be read).
inline std::string readText(const std::string& path)
{
  std::ifstream stream(path);
  std::ostringstream text;
  text << stream.rdbuf();
  return text.str();
}

/// `text` with the first occurrence of `from` replaced by `to` (which must exist: a test
/// failure, and `text` unchanged, if it does not).
inline std::string replaced(std::string text, const std::string& from, const std::string& to)
{
  const std::size_t at = text.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  if (at != std::string::npos)
  {
    text.replace(at, from.size(), to);
  }
  return text;
}

/// Runs `action`, expects a model::TemplateError whose message contains every piece (a test
/// failure for each missing piece, or if nothing is thrown; other exceptions propagate).
inline void expectError(
  const std::function<void()>& action, const std::vector<std::string>& pieces)
{
  try
  {
    action();
    ADD_FAILURE() << "no TemplateError thrown; expected one containing " << pieces.front();
  }
  catch (const model::TemplateError& error)
  {
    const std::string message = error.what();
    for (const std::string& piece : pieces)
    {
      EXPECT_NE(message.find(piece), std::string::npos)
        << "message \"" << message << "\" lacks \"" << piece << "\"";
    }
  }
}

/// The value of the model parameter `name` (a test failure and NaN if there is none).
inline double parameter(const model::BlockModel& model, const std::string& name)
{
  for (const auto& p : model.parameters)
  {
    if (p.first == name)
    {
      return p.second;
    }
  }
  ADD_FAILURE() << "no parameter " << name;
  return NAN;
}

/// @name Bit-for-bit comparison
/// Equality of the stored bits (memcmp), stricter than ==: 0.0 and -0.0 differ, a NaN
/// equals the same NaN. For results that must be reproduced exactly (determinism, round
/// trips through the model document, shared faces).
/// @{
inline bool sameBits(double a, double b)
{
  return std::memcmp(&a, &b, sizeof(double)) == 0;
}

inline bool sameBits(const Vec3& a, const Vec3& b)
{
  return std::memcmp(a.data(), b.data(), 3 * sizeof(double)) == 0;
}

/// Also false if the sizes differ.
inline bool sameBits(const std::vector<double>& a, const std::vector<double>& b)
{
  return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(double)) == 0;
}
/// @}

/// The nodes of every block of a model, as model::MultiBlockMesher writes them.
struct Grid
{
  /// Node counts (ni, nj, nk) of each block.
  std::vector<std::array<int, 3>> nodes;
  /// Coordinates of each block: x y z of node (i, j, k) at 3 * (i + ni * (j + nj * k)).
  std::vector<std::vector<double>> xyz;

  /// Node (i, j, k) of a block.
  Vec3 at(int block, int i, int j, int k) const
  {
    const auto& n = nodes[block];
    const double* p = &xyz[block][3 * ((static_cast<std::size_t>(k) * n[1] + j) * n[0] + i)];
    return Vec3(p[0], p[1], p[2]);
  }
};

/// Meshes every block of `model` with model::MultiBlockMesher: density `multiplier`, and
/// each direction capped at `cellCap` cells (0 = no cap, the mesher's default).
inline Grid meshAll(const model::BlockModel& model, double multiplier = 1.0, int cellCap = 0)
{
  model::MultiBlockMesher mesher(model, multiplier);
  mesher.setCellCap(cellCap);
  mesher.computeBoundaries();
  Grid grid;
  for (int b = 0; b < mesher.blockCount(); ++b)
  {
    grid.nodes.push_back(mesher.nodeCounts(b));
    const auto& n = grid.nodes.back();
    grid.xyz.emplace_back(3 * static_cast<std::size_t>(n[0]) * n[1] * n[2]);
    mesher.meshBlock(b, grid.xyz.back().data());
  }
  return grid;
}
/// Installs a runner on `threads` std::threads (chunks handed out in turn) and removes it
/// when it goes out of scope. `grainScale` makes even small grids split into chunks.
class ThreadRunner
{
public:
  explicit ThreadRunner(int threads, double grainScale = 1e-4)
  {
    setChunkRunner(
      [threads](long count, const std::function<void(long, long)>& body)
      {
        std::vector<std::thread> pool;
        for (int t = 0; t < threads; ++t)
        {
          pool.emplace_back(
            [=, &body]
            {
              for (long chunk = t; chunk < count; chunk += threads)
              {
                body(chunk, chunk + 1);
              }
            });
        }
        for (std::thread& thread : pool)
        {
          thread.join();
        }
      },
      threads, grainScale);
  }
  ~ThreadRunner() { setChunkRunner({}, 1); }
};
} // namespace test
} // namespace blockforge

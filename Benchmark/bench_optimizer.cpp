// The block optimizer on the blade-passage templates and every machine given: MinAngle
// classes before and after, run time (median of repetitions), evaluations per second,
// against two baselines on the same control points (Laplacian smoothing; a
// classy_blocks-style score of every block as one straight-edged cell). Not a test.
// Usage: bench_optimizer [--repetitions N] [--verbose] template.yaml input.inf [...]
#include "Optimizer.h"

#include "../Testing/Cxx/TestTurboInputs.h"

#include "CarrierGeometry.h"
#include "Template.h"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <string>
#include <vector>

using namespace blockforge;
using namespace blockforge::optimize;

namespace
{
double seconds(std::chrono::steady_clock::time_point since)
{
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - since).count();
}

double median(std::vector<double> values)
{
  std::sort(values.begin(), values.end());
  const std::size_t n = values.size();
  return n % 2 ? values[n / 2] : 0.5 * (values[n / 2 - 1] + values[n / 2]);
}

std::string classes(const GridMeasures& m)
{
  char text[128];
  std::snprintf(text, sizeof text, "%lld / %lld / %lld / %lld / %lld", m.classes[0],
    m.classes[1], m.classes[2], m.classes[3], m.classes[4]);
  return text;
}
} // namespace

int main(int argc, char** argv)
{
  int repetitions = 5;
  bool verbose = false;
  std::vector<std::pair<std::string, std::string>> cases;
  for (int a = 1; a < argc; ++a)
  {
    if (!std::strcmp(argv[a], "--repetitions") && a + 1 < argc)
    {
      repetitions = std::atoi(argv[++a]);
    }
    else if (!std::strcmp(argv[a], "--verbose"))
    {
      verbose = true;
    }
    else if (a + 1 < argc)
    {
      cases.emplace_back(argv[a], argv[a + 1]);
      ++a;
    }
  }
  for (const auto& [templateFile, inputFile] : cases)
  {
    const model::TemplateInputs inputs = test::readTemplateInputs(inputFile);
    model::CarrierGeometry geometry;
    const model::BlockModel model = model::loadTemplate(templateFile, {}, &inputs, &geometry);
    OptimizerSettings settings;
    std::vector<double> times;
    OptimizerResult result;
    for (int r = 0; r < repetitions; ++r)
    {
      model::CarrierGeometry copy = geometry;
      const auto begin = std::chrono::steady_clock::now();
      result = optimizeModel(model, copy, settings);
      times.push_back(seconds(begin));
    }
    std::printf("%s on %s\n", templateFile.c_str(), inputFile.c_str());
    std::printf("  variables %zu, locked by the boundary %zu\n", result.variables.size(),
      result.boundaryLocked.size());
    if (verbose)
    {
      for (const ControlVariable& v : result.variables)
      {
        std::printf("    %-12s %.6f in [%.6f, %.6f]\n", v.name.c_str(), v.start, v.low, v.high);
      }
      for (const std::string& name : result.boundaryLocked)
      {
        std::printf("    locked %s\n", name.c_str());
      }
    }
    std::printf("  before: min angle %.2f, classes %s\n", result.before.minAngle,
      classes(result.before).c_str());
    std::printf("  after:  min angle %.2f, classes %s\n", result.after.minAngle,
      classes(result.after).c_str());
    std::printf("  %d evaluations, median %.3f s, %.0f evaluations/s, stop: %s\n",
      result.search.evaluations, median(times), result.search.evaluations / median(times),
      result.search.stopReason.c_str());
  }
  return 0;
}

/**
 * @file blockforge.cpp
 * @brief The native command line: applies a template, optimizes its control points (the
 * block optimizer, as `python3 -m blockforge`; --no-optimize skips it), meshes it and
 * writes the grid in a solver format, without Python or VTK (start-up in milliseconds):
 *
 *   blockforge TEMPLATE [-i POINTS] [-p NAME=EXPR ...] [-d DENSITY] [-m GB] -o OUTPUT [--ascii]
 *              [--no-optimize] [--objective NAME] [--max-evaluations N]
 *              [--max-interface-ratio R]
 *
 * OUTPUT's extension picks the writer: DIR/NAME.foam (OpenFOAM case: DIR/constant/polyMesh
 * and an empty NAME.foam), NAME.xyz (Plot3D multiblock), NAME.cgns (CGNS), NAME.vtm (VTK
 * XML multiblock, points only, written without VTK). `python3 -m blockforge` takes the
 * same arguments and writes .vtm with the quality arrays.
 */
#include "Cgns.h"
#include "ExportModel.h"
#include "GridCheck.h"
#include "MemoryBudget.h"
#include "Mesher.h"
#include "Optimizer.h"
#include "Plot3D.h"
#include "PolyMesh.h"
#include "PrintableText.h"
#include "Template.h"
#include "VtkXml.h"
#include "TurboTemplateInputs.h"

#include <chrono>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <stdexcept>
#include <string>
#include <vector>

#include <csignal>

using namespace blockforge;

namespace
{
const char* const Usage =
  "usage: blockforge TEMPLATE [-i POINTS] [-p NAME=EXPR ...] [-d DENSITY] [-m GB] -o OUTPUT\n"
  "                  [--ascii] [--no-optimize] [--objective NAME] [--max-evaluations N]\n"
  "                  [--max-interface-ratio R]\n"
  "\n"
  "Applies a BlockForge template (to the point data of -i: a BladeGen .inf, an Info.txt or a\n"
  "point file), optimizes its control points (the BlockOptimizer with its defaults, as\n"
  "python3 -m blockforge), meshes it and writes the grid. The extension of OUTPUT picks the\n"
  "format:\n"
  "  DIR/NAME.foam  OpenFOAM case (DIR/constant/polyMesh, binary unless --ascii)\n"
  "  NAME.xyz       Plot3D multi-grid (binary unless --ascii), NAME.nmf beside it\n"
  "  NAME.cgns      CGNS (HDF5): zones, 1-to-1 and periodic connectivity, BCs by family\n"
  "  NAME.vtm       VTK XML multiblock, one .vts per block in a folder NAME.pieces-ID/\n"
  "                 beside it (points only, raw binary; python3 -m blockforge adds the\n"
  "                 quality arrays and --compress)\n"
  "Options:\n"
  "  -i, --input FILE        point data for a template with inputs\n"
  "  -p, --parameter N=EXPR  override a template parameter (repeatable)\n"
  "  -d, --density D         grid density multiplier (scales every cell count; above 0,\n"
  "                          at most 1000, at most 1,000,000 cells per block direction)\n"
  "  -m, --max-memory GB     refuse grids that would need more memory (default 0: what\n"
  "                          the machine has available)\n"
  "  -o, --output FILE       grid to write\n"
  "  --ascii                 ASCII instead of binary where the format has both\n"
  "  --no-optimize           keep the control points where the template put them\n"
  "  --objective NAME        what the optimizer improves: min-angle (default, the\n"
  "                          smallest element angle), non-orthogonality (OpenFOAM's\n"
  "                          largest) or min-angle-and-size-ratio\n"
  "  --max-evaluations N     the optimizer's trial budget (default 700, 1 to 1000000)\n"
  "  --max-interface-ratio R the optimizer refuses trials whose neighbour cells across a\n"
  "                          block interface differ more than R times (or than the\n"
  "                          placed grid's largest ratio, if more; default 1.6, 0: not\n"
  "                          held)\n"
  "The grid is written under a temporary name and moved into place: a failure leaves no\n"
  "partial grid and keeps an older one. Exit status 1 with a message on any error.\n";

struct Arguments
{
  std::string templateFile, input, output;
  model::ParameterOverrides parameters;
  double density = 1.0;
  double maximumMemory = 0.0; ///< GB, 0: what the machine has available
  bool ascii = false;
  bool optimize = true;
  optimize::ObjectiveKind objective = optimize::ObjectiveKind::MinAngle;
  int maximumEvaluations = optimize::SearchSettings{}.maxEvaluations;
  double maximumInterfaceRatio = optimize::ObjectiveSettings{}.maximumInterfaceRatio;
};

bool endsWith(const std::string& text, const std::string& suffix)
{
  return text.size() >= suffix.size() &&
    text.compare(text.size() - suffix.size(), suffix.size(), suffix) == 0;
}

Arguments parse(int argc, char** argv)
{
  Arguments args;
  for (int a = 1; a < argc; ++a)
  {
    const std::string arg = argv[a];
    auto value = [&]() -> std::string {
      if (a + 1 >= argc)
      {
        throw std::invalid_argument(arg + " needs a value");
      }
      return argv[++a];
    };
    if (arg == "-h" || arg == "--help")
    {
      std::fputs(Usage, stdout);
      std::exit(0);
    }
    else if (arg == "-i" || arg == "--input")
      args.input = value();
    else if (arg == "-o" || arg == "--output")
      args.output = value();
    else if (arg == "-d" || arg == "--density")
    {
      const std::string text = value();
      char* end = nullptr;
      args.density = std::strtod(text.c_str(), &end);
      if (end == text.c_str() || *end != '\0' || !(args.density > 0.0))
      {
        throw std::invalid_argument("-d needs a positive number, got '" + text + "'");
      }
    }
    else if (arg == "-m" || arg == "--max-memory")
    {
      const std::string text = value();
      char* end = nullptr;
      args.maximumMemory = std::strtod(text.c_str(), &end);
      if (end == text.c_str() || *end != '\0' || !(args.maximumMemory >= 0.0) ||
        !std::isfinite(args.maximumMemory))
      {
        throw std::invalid_argument("-m needs a number of GB >= 0, got '" + text + "'");
      }
    }
    else if (arg == "-p" || arg == "--parameter")
    {
      const std::string text = value();
      const std::size_t equals = text.find('=');
      if (equals == std::string::npos || equals == 0)
      {
        throw std::invalid_argument("expected NAME=EXPRESSION, got '" + text + "'");
      }
      args.parameters[text.substr(0, equals)] = text.substr(equals + 1);
    }
    else if (arg == "--ascii")
      args.ascii = true;
    else if (arg == "--no-optimize")
      args.optimize = false;
    else if (arg == "--objective")
    {
      const std::string name = value();
      if (name == "min-angle")
        args.objective = optimize::ObjectiveKind::MinAngle;
      else if (name == "non-orthogonality")
        args.objective = optimize::ObjectiveKind::NonOrthogonality;
      else if (name == "min-angle-and-size-ratio")
        args.objective = optimize::ObjectiveKind::MinAngleAndSizeRatio;
      else
        throw std::invalid_argument("--objective must be min-angle, non-orthogonality or "
                                    "min-angle-and-size-ratio, got '" + name + "'");
    }
    else if (arg == "--max-evaluations")
    {
      const std::string text = value();
      char* end = nullptr;
      errno = 0;
      const long count = std::strtol(text.c_str(), &end, 10);
      if (end == text.c_str() || *end != '\0' || errno != 0 || count < 1 || count > 1000000)
      {
        throw std::invalid_argument(
          "--max-evaluations needs a whole number from 1 to 1000000, got '" + text + "'");
      }
      args.maximumEvaluations = static_cast<int>(count);
    }
    else if (arg == "--max-interface-ratio")
    {
      const std::string text = value();
      char* end = nullptr;
      args.maximumInterfaceRatio = std::strtod(text.c_str(), &end);
      if (end == text.c_str() || *end != '\0' || !std::isfinite(args.maximumInterfaceRatio) ||
        !(args.maximumInterfaceRatio == 0.0 || args.maximumInterfaceRatio >= 1.0))
      {
        throw std::invalid_argument(
          "--max-interface-ratio needs 0 (not held) or a number >= 1, got '" + text + "'");
      }
    }
    else if (arg == "--compress")
      throw std::invalid_argument("--compress (zlib .vtm pieces) is only in python3 -m "
                                  "blockforge; the native command line writes raw binary");
    else if (!arg.empty() && arg[0] == '-')
      throw std::invalid_argument("unknown option " + arg);
    else if (args.templateFile.empty())
      args.templateFile = arg;
    else
      throw std::invalid_argument("more than one template given ('" + args.templateFile +
        "', '" + arg + "')");
  }
  if (args.templateFile.empty())
  {
    throw std::invalid_argument("no template given");
  }
  if (args.output.empty())
  {
    throw std::invalid_argument("no output given (-o DIR/NAME.foam)");
  }
  if (!endsWith(args.output, ".foam") && !endsWith(args.output, ".xyz") &&
    !endsWith(args.output, ".cgns") && !endsWith(args.output, ".vtm"))
  {
    throw std::invalid_argument("the output must end in .foam (OpenFOAM case), .xyz (Plot3D), "
                                ".cgns or .vtm (VTK XML multiblock), got '" +
      args.output + "'");
  }
  return args;
}

/// The point sets the way vtkBlockTemplate hands on the TurboPointSetsReader's output.
model::TemplateInputs readInputs(const std::string& file)
{
  const io::TurboPointSets sets = io::readTurboPointSets(file);
  for (const std::string& warning : sets.warnings)
  {
    std::fprintf(stderr, "warning: %s\n", printableText(warning).c_str());
  }
  return io::templateInputs(sets, file);
}

/// Writes the grid in the format of the output's extension; prints what was written.
void writeGrid(const exporting::ExportGrid& grid, const Arguments& args)
{
  if (endsWith(args.output, ".cgns"))
  {
    exporting::writeCgns(grid, args.output);
    std::printf("blocks: %zu   cells: %lld   nodes: %lld (CGNS zones), interfaces: %zu\n",
      grid.blocks.size(), grid.cellCount(), grid.nodeCount(), grid.interfaces.size());
    return;
  }
  if (endsWith(args.output, ".vtm"))
  {
    exporting::writeVtkMultiBlock(grid, args.output);
    std::printf("blocks: %zu   cells: %lld   nodes: %lld (VTK XML multiblock, points only)\n",
      grid.blocks.size(), grid.cellCount(), grid.nodeCount());
    return;
  }
  if (endsWith(args.output, ".xyz"))
  {
    exporting::Plot3DOptions options;
    options.binary = !args.ascii;
    exporting::writePlot3D(grid, args.output, options);
    const std::string map = args.output.substr(0, args.output.size() - 4) + ".nmf";
    exporting::writePlot3DNeutralMap(grid, map);
    std::printf("blocks: %zu   cells: %lld   nodes: %lld (Plot3D, patches and interfaces in %s)\n",
      grid.blocks.size(), grid.cellCount(), grid.nodeCount(), map.c_str());
    return;
  }
  exporting::FoamWriteOptions options;
  options.binary = !args.ascii;
  const exporting::FoamSummary mesh = exporting::writeFoamCase(grid, args.output, options);
  std::printf("blocks: %zu   cells: %d   points: %d   faces: %d (%d internal, %d triangles)\n",
    grid.blocks.size(), mesh.cells, mesh.points, mesh.faces, mesh.internalFaces,
    mesh.triangleFaces);
  for (const exporting::FoamPatch& patch : mesh.patches)
  {
    std::printf("  patch %-16s %-9s %8d faces\n", patch.name.c_str(), patch.type.c_str(),
      patch.faceCount);
  }
}

double seconds(std::chrono::steady_clock::time_point since)
{
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - since).count();
}
} // namespace

int main(int argc, char** argv)
{
  // A file-size limit must end as a write error (EFBIG), not a killed process.
  std::signal(SIGXFSZ, SIG_IGN);
  Arguments args;
  try
  {
    args = parse(argc, argv);
  }
  catch (const std::exception& error)
  {
    std::fprintf(stderr, "error: %s\n\n%s", printableText(error.what()).c_str(), Usage);
    return 2;
  }
  try
  {
    const auto start = std::chrono::steady_clock::now();
    model::TemplateInputs inputs;
    if (!args.input.empty())
    {
      inputs = readInputs(args.input);
    }
    model::CarrierGeometry carriers;
    model::BlockModel model = model::loadTemplate(
      args.templateFile, args.parameters, args.input.empty() ? nullptr : &inputs, &carriers);
    const double templateTime = seconds(start);

    // The optimizer with vtkBlockOptimizer's defaults, measuring the final cells (the grid
    // at the density asked for, as mesh_template): both command lines write the same grid.
    const auto optimizeStart = std::chrono::steady_clock::now();
    std::string optimizerLine;
    if (args.optimize)
    {
      optimize::OptimizerSettings settings;
      settings.densityMultiplier = args.density;
      settings.maximumMemory = args.maximumMemory;
      settings.objective.kind = args.objective;
      settings.search.maxEvaluations = args.maximumEvaluations;
      settings.objective.maximumInterfaceRatio = args.maximumInterfaceRatio;
      const optimize::OptimizerResult result = optimize::optimizeModel(model, carriers, settings);
      model = result.model;
      char line[256];
      std::snprintf(line, sizeof line,
        "optimizer: smallest element angle %.2f -> %.2f deg, %d evaluations, %zu parameters\n",
        result.before.minAngle, result.after.minAngle, result.search.evaluations,
        result.variables.size());
      optimizerLine = line;
    }
    const double optimizeTime = seconds(optimizeStart);

    const auto meshStart = std::chrono::steady_clock::now();
    model::MultiBlockMesher mesher(model, carriers, args.density);
    model::BlockNodeCounts counts;
    for (int b = 0; b < mesher.blockCount(); ++b)
    {
      counts.push_back(mesher.nodeCounts(b));
    }
    model::checkGridMemory(
      counts, args.maximumMemory, "lower the density multiplier or the cell counts");
    mesher.computeBoundaries();
    std::vector<exporting::LargeVector<double>> nodes(mesher.blockCount());
    std::vector<exporting::GridBlock> blocks(mesher.blockCount());
    for (int b = 0; b < mesher.blockCount(); ++b)
    {
      blocks[b].name = model.blocks[b].name;
      blocks[b].nodes = mesher.nodeCounts(b);
      nodes[b].resize(static_cast<std::size_t>(blocks[b].nodeCount()) * 3);
      mesher.meshBlock(b, nodes[b].data());
      model::checkBlockCells(model, b, blocks[b].nodes, nodes[b].data());
      blocks[b].xyz = nodes[b].data();
    }
    const exporting::ExportGrid grid = exporting::exportGrid(model, std::move(blocks));
    const double meshTime = seconds(meshStart);

    std::printf("template: %s\n", printableText(args.templateFile).c_str());
    if (!args.input.empty())
    {
      std::printf("input: %s\n", printableText(args.input).c_str());
    }
    std::fputs(optimizerLine.c_str(), stdout);
    const auto writeStart = std::chrono::steady_clock::now();
    writeGrid(grid, args);
    const double writeTime = seconds(writeStart);
    std::printf("time [s]: template %.3f, optimize %.3f, mesh %.3f, write %.3f, total %.3f\n",
      templateTime, optimizeTime, meshTime, writeTime, seconds(start));
    std::printf("grid written to %s%s\n", printableText(args.output).c_str(),
      endsWith(args.output, ".cgns") || endsWith(args.output, ".vtm") ? "" : args.ascii ? " (ASCII)" : " (binary)");
  }
  catch (const std::exception& error)
  {
    std::fprintf(stderr, "error: %s\n", printableText(error.what()).c_str());
    return 1;
  }
  return 0;
}

/**
 * @class   vtkTurboPointSetsReader
 * @brief   Reads the input data of the paper's blade-passage templates: hub contour,
 *          shroud contour and blade sections, as TurboGrid/BladeGen exports (.inf +
 *          .curve/.crv) or multi-section point files (.dat, .csv, .txt) with an Info.txt.
 *
 * FileName may be
 * - a BladeGen `.inf` file: it names the hub, shroud and profile files (relative to the
 *   .inf), the axis, the blade count and the units;
 * - an `Info.txt` (keys "No of blades", "Axis of rotation", "Coordinates unit"): the
 *   point files beside it are taken by their names (`*hub*`, `*shroud*`, `*profile*`);
 * - one point file: a `.inf` beside it that names it, or else an `Info.txt` beside it,
 *   supplies the machine data, and the files beside it with the same name apart from the
 *   role word complete the set (opening profile_R37.dat also reads hub_R37.dat and
 *   shroud_R37.dat). A file whose name says neither hub nor shroud is read as profiles.
 * HubFile, ShroudFile and ProfileFile replace the files found that way. BladeCount, Axis
 * and Units are used only where the files do not say.
 *
 * The parsing lives in Filters/IO/TurboPointSets (plain C++, unit-tested without VTK);
 * this class only translates its result.
 *
 * Output: a vtkMultiBlockDataSet with
 * - block 0 "Hub" and block 1 "Shroud": a vtkPolyData with one polyline through the
 *   contour points (a null block when the set has no such file);
 * - block 2 "Profiles": a vtkMultiBlockDataSet of one vtkPolyData polyline per blade
 *   section, named "Profile k (s%)" (prefixed by the blade name when a `## name` line
 *   tells several blades apart), with field data "SpanFraction" (s / 100; spread evenly
 *   when the file gives no spans, then "SpanGiven" is 0), "SpanGiven", "ProfileNumber",
 *   "Closure" ("closed", "joined", "segment" (first point repeated), "capped straight",
 *   "capped rounded" or "open": what
 *   was done to a section whose first and last points differ) and "GapFraction" (that
 *   gap over the chord, 0 when the file closed the section).
 * Every curve also carries "SourceFile" and "FirstLine" in its field data.
 *
 * Units: point coordinates are converted to metres, so that every later stage works in
 * SI whatever the export; the file's unit stays in the root's field data: "Units"
 * (M, CM, MM, IN or FT as found) and "UnitScale" (metres per file unit). The machine
 * data is there too: "BladeCount" (blade sets around the machine, the rotational
 * periodicity; 0 when unknown), "BladesPerSet", "Axis" (unit vector of the machine axis,
 * through the origin of the file's coordinates) and "AxisName" ("X", "-Z", ...).
 * Coordinates are not rotated: the axis is wherever the export put it.
 *
 * Sections: every comment or blank line between point rows starts a new section. Open
 * sections are closed (TrailingEdgeCap), sections are put in span order, and contours or
 * sections that turn back or cross themselves are refused (see Filters/IO/SectionChecks.h).
 *
 * Errors (missing or malformed file, malformed row, NaN, a section with fewer than 4
 * points, unknown unit or axis, sections whose header spans contradict their place between
 * hub and shroud, kinked or self-crossing curves) are reported with vtkErrorMacro as
 * "file:line: what" and leave the output empty. Non-fatal remarks (a part missing from
 * the .inf, spans guessed, sections closed or sorted) are warnings. In parallel, piece 0 holds the curves; the other pieces have the
 * same block structure with null leaves.
 *
 * @sa vtkBlockTemplateSource vtkBlockMesher
 */
#ifndef vtkTurboPointSetsReader_h
#define vtkTurboPointSetsReader_h

#include "BlockForgeFiltersModule.h"
#include "vtkMultiBlockDataSetAlgorithm.h"

#include <memory>
#include <string>
#include <vector>

class BLOCKFORGEFILTERS_EXPORT vtkTurboPointSetsReader : public vtkMultiBlockDataSetAlgorithm
{
public:
  static vtkTurboPointSetsReader* New();
  vtkTypeMacro(vtkTurboPointSetsReader, vtkMultiBlockDataSetAlgorithm);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  ///@{
  /// The file to open: a .inf, an Info.txt or a point file (see the class comment).
  vtkSetStringMacro(FileName);
  vtkGetStringMacro(FileName);
  ///@}

  ///@{
  /// Point files that replace those named by or found beside FileName (empty: none).
  /// A relative path is relative to FileName's folder.
  vtkSetStringMacro(HubFile);
  vtkGetStringMacro(HubFile);
  vtkSetStringMacro(ShroudFile);
  vtkGetStringMacro(ShroudFile);
  vtkSetStringMacro(ProfileFile);
  vtkGetStringMacro(ProfileFile);
  ///@}

  ///@{
  /// Number of blade sets when the files do not say (0: unknown).
  vtkSetClampMacro(BladeCount, int, 0, 100000);
  vtkGetMacro(BladeCount, int);
  ///@}

  ///@{
  /// Machine axis when the files do not say: X, Y, Z (optionally signed) or three
  /// numbers. Default Z, TurboGrid's convention.
  vtkSetStringMacro(Axis);
  vtkGetStringMacro(Axis);
  ///@}

  ///@{
  /// Unit of the coordinates when the files do not say: M, CM, MM, IN or FT (any case).
  /// Default M.
  vtkSetStringMacro(Units);
  vtkGetStringMacro(Units);
  ///@}

  ///@{
  /// How a blade section left open at a blunt trailing edge (a gap between 0.2 % and 5 %
  /// of the chord) is closed: Straight (0, default) or Rounded (1, a half circle across
  /// the gap). Gaps up to 0.2 % are joined, larger than 5 % left open.
  enum TrailingEdgeCaps
  {
    Straight = 0,
    Rounded = 1
  };
  vtkSetClampMacro(TrailingEdgeCap, int, Straight, Rounded);
  vtkGetMacro(TrailingEdgeCap, int);
  ///@}

  /// 1 if the file looks like one this reader reads (a description file with a known key,
  /// or X Y Z rows), judged from its first 64 kB. Lets ParaView choose between readers
  /// that share an extension (.dat is also Tecplot's).
  int CanReadFile(const char* fileName);

  ///@{
  /**
   * What the files said, after the last read (RequestInformation reads them too, so
   * ParaView's panel shows them before Apply): the blade count, axis and unit as found,
   * or "(not in the files: <fallback> used)"; the description file read ("" if none).
   */
  const char* GetBladeCountInFiles() const { return this->BladeCountFound.c_str(); }
  const char* GetAxisInFiles() const { return this->AxisFound.c_str(); }
  const char* GetUnitsInFiles() const { return this->UnitsFound.c_str(); }
  const char* GetDescriptionFileRead() const { return this->DescriptionFound.c_str(); }
  ///@}

  /// Reads the files again at the next update although nothing changed (Reload Files).
  void Reload() { this->Modified(); }

  /// Also newer when a file read last time (or named now) was edited on disk.
  vtkMTimeType GetMTime() override;

protected:
  vtkTurboPointSetsReader();
  ~vtkTurboPointSetsReader() override;

  int RequestInformation(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;
  int RequestData(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;

  char* FileName = nullptr;
  char* HubFile = nullptr;
  char* ShroudFile = nullptr;
  char* ProfileFile = nullptr;
  int BladeCount = 0;
  char* Axis = nullptr;
  char* Units = nullptr;
  int TrailingEdgeCap = Straight;

private:
  /// Reads the files and notes what they said; fills `result` (if given) with the blocks,
  /// the curves only when `holdsData`.
  void ReadSets(vtkMultiBlockDataSet* result, bool holdsData);

  std::string BladeCountFound, AxisFound, UnitsFound, DescriptionFound;
  struct Internals;
  std::unique_ptr<Internals> Internal;

  vtkTurboPointSetsReader(const vtkTurboPointSetsReader&) = delete;
  void operator=(const vtkTurboPointSetsReader&) = delete;
};

#endif

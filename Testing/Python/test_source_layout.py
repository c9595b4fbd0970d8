"""The layering of the sources and their size, checked on every header and source file
under Filters/ (plain Python, no build needed).

Layers, lowest first: Filters/Core (numerical core, Eigen only) < Filters/Model (the
block model, templates and mesher; yaml-cpp and muParser privately) < Filters/IO,
Filters/Export and Filters/Model/Optimize (the point-set reader and its hand-over to the
template, the solver writers, the optimizer) < the VTK adapters in Filters/ itself. A
file may include files of its own layer or below, never above: a quoted include is
resolved as the compiler would (next to the file, else on the include path of the
libraries, which is every Filters folder) and its folder's layer compared. VTK headers
are for the adapters only; yaml-cpp and muParser stay out of Core.

No file under Filters/ may have more than 1,500 lines (the project's limit).
"""
import os
import re
import sys
import unittest

SOURCE = os.environ.get("BLOCKFORGE_SOURCE_DIR") or os.path.abspath(
    os.path.join(os.path.dirname(__file__), "..", ".."))
FILTERS = os.path.join(SOURCE, "Filters")
SUFFIXES = (".h", ".cpp", ".cxx", ".hpp", ".txx")
LINE_LIMIT = 1500

# folder (relative to Filters) -> layer; the adapters in Filters/ itself are the top.
LAYERS = {"Core": 0, "Model": 1, "IO": 2, "Export": 2, "Model/Optimize": 2, "": 3}
LAYER_NAMES = {0: "Core", 1: "Model", 2: "IO/Export/Optimize", 3: "VTK adapters"}
INCLUDE = re.compile(r'^\s*#\s*include\s*([<"])([^>"]+)[>"]', re.MULTILINE)


def folder_of(path):
    """The folder of `path` relative to Filters, '' for Filters itself."""
    relative = os.path.relpath(os.path.dirname(os.path.abspath(path)), FILTERS)
    return "" if relative == "." else relative.replace(os.sep, "/")


def layer_of(path):
    folder = folder_of(path)
    while folder not in LAYERS:
        folder = folder.rsplit("/", 1)[0] if "/" in folder else ""
    return LAYERS[folder]


def source_files():
    files = []
    for root, _, names in os.walk(FILTERS):
        files += [os.path.join(root, n) for n in sorted(names) if n.endswith(SUFFIXES)]
    return sorted(files)


def resolve(including, name, by_basename):
    """The file a quoted include names, or None when it is not under Filters."""
    beside = os.path.normpath(os.path.join(os.path.dirname(including), name))
    if os.path.isfile(beside):
        return beside
    candidates = by_basename.get(os.path.basename(name), [])
    matching = [c for c in candidates if c.replace(os.sep, "/").endswith("/" + name)]
    if len(matching) > 1:
        raise AssertionError("%s: include \"%s\" is ambiguous: %s" % (
            os.path.relpath(including, SOURCE), name,
            ", ".join(os.path.relpath(m, SOURCE) for m in matching)))
    return matching[0] if matching else None


def layering_violations(files):
    by_basename = {}
    for f in files:
        by_basename.setdefault(os.path.basename(f), []).append(f)
    violations = []
    for f in files:
        layer = layer_of(f)
        with open(f, encoding="utf-8", errors="replace") as stream:
            text = stream.read()
        for match in INCLUDE.finditer(text):
            kind, name = match.group(1), match.group(2)
            line = text.count("\n", 0, match.start()) + 1
            where = "%s:%d" % (os.path.relpath(f, SOURCE), line)
            base = os.path.basename(name)
            if layer < 3 and (base.startswith("vtk") or name.startswith("vtk")):
                violations.append("%s includes VTK header %s in layer %s" % (
                    where, name, LAYER_NAMES[layer]))
                continue
            if layer == 0 and kind == "<" and (name.startswith("yaml-cpp") or
                                               name.lower().startswith("muparser")):
                violations.append("%s includes %s in Core (Eigen only)" % (where, name))
                continue
            if kind != '"':
                continue
            target = resolve(f, name, by_basename)
            if target is None:
                continue  # a generated or third-party header
            if layer_of(target) > layer:
                violations.append("%s (%s) includes %s (%s): upwards" % (
                    where, LAYER_NAMES[layer], os.path.relpath(target, SOURCE),
                    LAYER_NAMES[layer_of(target)]))
    return violations


class SourceLayout(unittest.TestCase):
    def test_every_folder_has_a_layer(self):
        files = source_files()
        folders = sorted({folder_of(f) for f in files})
        # every folder with sources is one of the layers or inside one: a new folder
        # must be given its layer here (it would not fall to the adapters' unseen)
        for folder in folders:
            inside = folder
            while inside and inside not in LAYERS:
                inside = inside.rsplit("/", 1)[0] if "/" in inside else ""
            self.assertTrue(folder == "" or inside != "", "no layer for Filters/" + folder)
        for expected in ("Core", "Model", "Model/Optimize", "IO", "Export", ""):
            self.assertIn(expected, folders)
        self.assertGreater(len(files), 100)

    def test_no_include_runs_upwards(self):
        violations = layering_violations(source_files())
        self.assertEqual(violations, [], "\n".join(violations))

    def test_the_check_sees_an_upward_include(self):
        # The resolution must find a real upward include: a Core file naming a Model
        # header, a Model file naming a VTK header.
        core = os.path.join(FILTERS, "Core", "Probe.cpp")
        by_basename = {}
        for f in source_files():
            by_basename.setdefault(os.path.basename(f), []).append(f)
        target = resolve(core, "BlockModel.h", by_basename)
        self.assertIsNotNone(target)
        self.assertGreater(layer_of(target), layer_of(core))
        self.assertEqual(layer_of(os.path.join(FILTERS, "Model", "Probe.cpp")), 1)
        self.assertEqual(layer_of(os.path.join(FILTERS, "vtkProbe.cxx")), 3)

    def test_no_file_above_the_line_limit(self):
        long_files = []
        for f in source_files():
            with open(f, encoding="utf-8", errors="replace") as stream:
                lines = sum(1 for _ in stream)
            if lines > LINE_LIMIT:
                long_files.append("%s: %d lines" % (os.path.relpath(f, SOURCE), lines))
        self.assertEqual(long_files, [], "\n".join(long_files))


if __name__ == "__main__":
    sys.exit(unittest.main(verbosity=2, exit=False).result.wasSuccessful() is False)

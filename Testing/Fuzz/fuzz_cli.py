"""Mutation fuzzer over BlockForge's command line entry point (``blockforge.__main__.main``):
the point file reader, the template engine, the mesher, quality and the grid writer.

Seeds are the templates of ``Templates/`` and ``Testing/Data/`` and the point data of
``Data/``. Every case mutates one seed file (bytes flipped, stray non-UTF-8 bytes, lines
deleted, duplicated, swapped or reversed, numbers replaced by NaN, infinities, huge or
tiny values and ``1/0``, coordinates scaled, lone-CR line ends, a second YAML document,
truncation) and/or the arguments (density multiplier, parameter overrides), runs it and
puts the outcome in one class:

- ``error``: exit status 1 with one clear message on stderr ("error: ..."), nothing written;
- ``success``: exit status 0, a grid written, finite, no cell with ScaledJacobian <= 0
  (one case in ten writes a solver format, .foam, .xyz or .cgns, only checked to exist);
- ``invalid``: exit status 0 but the grid is missing, not finite or has inverted cells, or
  exit status 1 with a grid written anyway, or a message that is not one readable line;
- ``crash``: a Python traceback, a signal, any other exit status (the worker dies);
- ``hang``: no answer within ``--case-timeout`` seconds.

Cases run in a worker process that imports VTK once and runs case after case; a crash or
hang costs only the worker, which is restarted (the case is recorded). The worker runs
under an address-space limit (``--memory-limit``), so huge grids must be refused by the
memory estimate rather than crash. Deterministic for a given ``--seed``.

Usage:  python3 fuzz_cli.py [--cases N] [--seconds S] [--seed K] [--json out.json]
(CTest: Fuzz.cli runs 300 cases with seed 12, at most 120 s.)
Exit status 1 when a case crashed, hung or gave invalid output (``--allow`` lists the
classes that do not fail the run).
"""
import argparse
import json
import os
import random
import re
import resource
import select
import shutil
import subprocess
import sys
import tempfile
import time

SOURCE = os.environ.get("BLOCKFORGE_SOURCE_DIR",
                        os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", ".."))
OUTCOMES = ("error", "success", "invalid", "crash", "hang")

# (template, point data folder, main point file or None)
PASSAGES = [("Templates/axial_passage_oh.yaml", "Data/distributor", "BladeGen.inf"),
            ("Templates/axial_passage_h.yaml", "Data/distributor", "BladeGen.inf"),
            ("Templates/axial_passage_oh.yaml", "Data/rotor37/turbogrid", "BladeGen.inf"),
            ("Templates/axial_passage_h.yaml", "Data/rotor37/dat", "Info.txt")]
STANDALONE = ["Templates/cylinder_in_box.yaml", "Templates/annular_sector.yaml",
              "Templates/wedge_sector.yaml", "Testing/Data/two_blocks.yaml",
              "Testing/Data/annular_passage.yaml", "Testing/Data/plate_blade.yaml",
              "Testing/Data/feature_aligned_blade.yaml"]
STRANGE_NUMBERS = ["nan", "inf", "-inf", "1e308", "-1e308", "0", "-0", "1e-300", "1e6",
                   "-1", "2147483647", "1/0", "0.001", "1e9"]
DENSITIES = ["inf", "1e308", "1000", "0", "-1", "nan", "1e-9", "0.5", "2", "150", "3"]


# --- mutations -----------------------------------------------------------------------------
def _lines(data):
    return data.split(b"\n")


def mutate(data, rng):
    """One mutation of *data* (bytes): (new bytes, description)."""
    lines = _lines(data)
    kind = rng.choice(["flip", "stray", "delete", "duplicate", "swap", "reverse", "number",
                       "number", "scale", "truncate", "lone_cr", "document", "expression"])
    if kind == "flip" and data:
        at = rng.randrange(len(data))
        return data[:at] + bytes([rng.randrange(256)]) + data[at + 1:], f"flip byte {at}"
    if kind == "stray":
        line = rng.randrange(len(lines))
        stray = rng.choice([b"\xff", b"\xc3", b"\xe2\x82", b"\x80"])
        lines[line] = lines[line] + stray if rng.random() < 0.5 else stray + lines[line]
        return b"\n".join(lines), f"stray byte in line {line + 1}"
    if kind in ("delete", "duplicate") and len(lines) > 1:
        line = rng.randrange(len(lines))
        if kind == "delete":
            del lines[line]
        else:
            lines.insert(line, lines[line])
        return b"\n".join(lines), f"{kind} line {line + 1}"
    if kind == "swap" and len(lines) > 2:
        a, b = rng.sample(range(len(lines)), 2)
        lines[a], lines[b] = lines[b], lines[a]
        return b"\n".join(lines), f"swap lines {a + 1} {b + 1}"
    if kind == "reverse" and len(lines) > 12:
        start = rng.randrange(len(lines) - 10)
        lines[start:start + 10] = lines[start:start + 10][::-1]
        return b"\n".join(lines), f"reverse lines {start + 1}-{start + 10}"
    numbers = list(re.finditer(rb"-?\d+(\.\d*)?([eE][-+]?\d+)?", data))
    if kind == "number" and numbers:
        match = rng.choice(numbers)
        value = rng.choice(STRANGE_NUMBERS).encode()
        return (data[:match.start()] + value + data[match.end():],
                f"number at {match.start()} -> {value.decode()}")
    if kind == "scale" and numbers:
        picked = sorted(rng.sample(numbers, min(4, len(numbers))), key=lambda m: m.start())
        factor = rng.choice([1000.0, 1e-3, -1.0, 1e6])
        out, last = b"", 0
        for match in picked:
            try:
                value = float(match.group(0)) * factor
            except ValueError:
                continue
            out += data[last:match.start()] + repr(value).encode()
            last = match.end()
        return out + data[last:], f"4 numbers scaled by {factor}"
    if kind == "truncate" and data:
        at = rng.randrange(len(data))
        return data[:at], f"truncated at {at}"
    if kind == "lone_cr":
        return data.replace(b"\n", b"\r"), "lone CR line ends"
    if kind == "document":
        return data + b"\n---\nblockforge: 1\n", "second YAML document"
    if kind == "expression" and numbers:
        match = rng.choice(numbers)
        value = rng.choice([b"1/0", b"sqrt(-1)", b"1e308*10", b"(", b"x_undefined"])
        return (data[:match.start()] + value + data[match.end():],
                f"expression {value.decode()} at {match.start()}")
    return data, "unchanged"


def template_parameters(text):
    """Names in the template's parameters: section."""
    names, inside = [], False
    for line in text.splitlines():
        if re.match(r"^parameters\s*:", line):
            inside = True
            continue
        if inside:
            match = re.match(r"^\s+([A-Za-z_][A-Za-z0-9_]*)\s*:", line)
            if match:
                names.append(match.group(1))
            elif line and not line[0].isspace() and not line.startswith("#"):
                break
    return names


def make_case(rng, index, work):
    """Files of case *index* in the folder *work* and its argument list:
    (argv, output path, description)."""
    folder = os.path.join(work, f"case{index}")
    os.makedirs(folder)
    # mostly .vtm (read back and checked cell by cell), sometimes a solver format
    extension = rng.choice([".vtm"] * 17 + [".foam", ".xyz", ".cgns"])
    output = os.path.join(folder, "out", "grid" + extension)
    use_passage = rng.random() < 0.4
    if use_passage:
        template, data_folder, main_file = rng.choice(PASSAGES)
        copy = os.path.join(folder, "data")
        shutil.copytree(os.path.join(SOURCE, data_folder), copy,
                        ignore=shutil.ignore_patterns("*.md", "*.py"))
        argv_input = ["-i", os.path.join(copy, main_file)]
        candidates = [os.path.join(copy, name) for name in sorted(os.listdir(copy))]
    else:
        template = rng.choice(STANDALONE)
        argv_input, candidates = [], []
    template_copy = os.path.join(folder, os.path.basename(template))
    shutil.copy(os.path.join(SOURCE, template), template_copy)
    candidates.append(template_copy)
    description = [template]
    if argv_input:
        description.append("-i " + os.path.relpath(argv_input[1], folder))
    argv = [template_copy] + argv_input + ["-o", output]
    for _ in range(rng.choice([0, 1, 1, 1, 2])):
        victim = rng.choice(candidates)
        with open(victim, "rb") as stream:
            data = stream.read()
        data, what = mutate(data, rng)
        with open(victim, "wb") as stream:
            stream.write(data)
        description.append(f"{os.path.basename(victim)}: {what}")
    if rng.random() < 0.2:
        density = rng.choice(DENSITIES)
        argv += ["-d", density]
        description.append(f"-d {density}")
    if rng.random() < 0.2:
        with open(os.path.join(SOURCE, template), encoding="utf-8") as stream:
            names = template_parameters(stream.read())
        if names:
            override = f"{rng.choice(names)}={rng.choice(STRANGE_NUMBERS)}"
            argv += ["-p", override]
            description.append(f"-p {override}")
    return argv, output, "; ".join(description)


# --- the worker: runs cases in one process ---------------------------------------------------
def grid_problem(path):
    """Why the written grid *path* is not a valid grid, or None."""
    import numpy as np
    from vtkmodules.numpy_interface import dataset_adapter as dsa
    from vtkmodules.vtkIOXML import vtkXMLMultiBlockDataReader

    if not os.path.isfile(path):
        return "exit 0 but no grid written"
    if not path.endswith(".vtm"):
        return None if os.path.getsize(path) > 0 or path.endswith(".foam") else "empty file"
    reader = vtkXMLMultiBlockDataReader()
    reader.SetFileName(path)
    reader.Update()
    iterator = reader.GetOutput().NewIterator()
    iterator.InitTraversal()
    blocks = 0
    while not iterator.IsDoneWithTraversal():
        block = dsa.WrapDataObject(iterator.GetCurrentDataObject())
        blocks += 1
        if not np.all(np.isfinite(block.Points)):
            return "coordinates not finite"
        jacobian = block.CellData["ScaledJacobian"]
        if jacobian is None or not np.all(np.isfinite(jacobian)):
            return "no finite ScaledJacobian"
        if np.min(jacobian) <= 0.0:
            return f"inverted cells (min ScaledJacobian {np.min(jacobian):.3g})"
        iterator.GoToNextItem()
    return None if blocks else "empty grid"


def worker(memory_limit):
    """Reads cases (JSON lines: argv, output) on stdin; answers with JSON lines."""
    import contextlib
    import io
    import traceback

    if memory_limit > 0:
        limit = int(memory_limit * 2**30)
        resource.setrlimit(resource.RLIMIT_AS, (limit, limit))
    # The protocol gets the real stdout; whatever C++ or VTK print goes to stderr.
    protocol = os.fdopen(os.dup(1), "w")
    os.dup2(2, 1)
    from blockforge.__main__ import main

    for line in sys.stdin:
        case = json.loads(line)
        stdout, stderr = io.StringIO(), io.StringIO()
        answer = {}
        try:
            with contextlib.redirect_stdout(stdout), contextlib.redirect_stderr(stderr):
                status = main(case["argv"])
            answer["status"] = status
        except SystemExit as exit_:  # argparse errors
            answer["status"] = exit_.code if isinstance(exit_.code, int) else 1
        except BaseException:  # noqa: B902 - a traceback is the finding
            answer["status"] = "traceback"
            answer["traceback"] = traceback.format_exc()[-2000:]
        answer["stderr"] = stderr.getvalue()[-2000:]
        if answer["status"] == 0:
            try:
                answer["grid_problem"] = grid_problem(case["output"])
            except Exception as error:  # noqa: BLE001
                answer["grid_problem"] = f"grid unreadable: {error}"
        else:
            answer["written"] = os.path.exists(case["output"])
        protocol.write(json.dumps(answer) + "\n")
        protocol.flush()


class Worker:
    def __init__(self, memory_limit):
        self.log = tempfile.TemporaryFile(mode="w+", errors="backslashreplace")
        self.process = subprocess.Popen(
            [sys.executable, os.path.abspath(__file__), "--worker",
             "--memory-limit", str(memory_limit)],
            stdin=subprocess.PIPE, stdout=subprocess.PIPE, stderr=self.log,
            text=True, errors="backslashreplace")

    def run(self, argv, output, timeout):
        """The worker's answer, or {"status": "hang"} / {"status": "crash", ...}."""
        self.process.stdin.write(json.dumps({"argv": argv, "output": output}) + "\n")
        self.process.stdin.flush()
        ready, _, _ = select.select([self.process.stdout], [], [], timeout)
        if not ready:
            self.stop()
            return {"status": "hang"}
        line = self.process.stdout.readline()
        if not line:
            code = self.process.wait()
            self.log.seek(0)
            detail = self.log.read()[-1500:]
            return {"status": "crash", "exit": code, "stderr": detail}
        return json.loads(line)

    def stop(self):
        if self.process.poll() is None:
            self.process.kill()
        self.process.wait()
        self.log.close()


def classify(answer):
    status = answer["status"]
    if status in ("hang", "crash", "traceback"):
        return "hang" if status == "hang" else "crash"
    if status == 0:
        return "invalid" if answer.get("grid_problem") else "success"
    message = answer.get("stderr", "")
    if status == 1 and answer.get("written"):
        return "invalid"
    # argparse usage errors (status 2) are clear errors too
    if status in (1, 2) and message.strip() and "Traceback" not in message:
        return "error"
    return "crash"


def main():
    parser = argparse.ArgumentParser(description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--cases", type=int, default=0,
                        help="number of cases (0: as many as --seconds allow)")
    parser.add_argument("--seconds", type=float, default=60.0,
                        help="time budget (no new case starts after it)")
    parser.add_argument("--seed", type=int, default=12)
    parser.add_argument("--case-timeout", type=float, default=20.0)
    parser.add_argument("--memory-limit", type=float, default=6.0, help="GB for the worker")
    parser.add_argument("--json", help="write every case and its outcome here")
    parser.add_argument("--allow", default="", help="comma-separated classes that pass")
    parser.add_argument("--worker", action="store_true", help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.worker:
        worker(args.memory_limit)
        return 0

    rng = random.Random(args.seed)
    work = tempfile.mkdtemp(prefix="blockforge-fuzz-")
    counts = {outcome: 0 for outcome in OUTCOMES}
    findings, records = [], []
    runner = Worker(args.memory_limit)
    start = time.monotonic()
    index = 0
    try:
        while ((not args.cases or index < args.cases)
               and time.monotonic() - start < args.seconds):
            argv, output, description = make_case(rng, index, work)
            began = time.monotonic()
            answer = runner.run(argv, output, args.case_timeout)
            outcome = classify(answer)
            if answer["status"] in ("hang", "crash"):
                runner = Worker(args.memory_limit)
            counts[outcome] += 1
            record = {"case": index, "input": description, "outcome": outcome,
                      "seconds": round(time.monotonic() - began, 3),
                      "message": (answer.get("stderr") or "").strip()[:300],
                      "detail": answer.get("grid_problem") or answer.get("traceback", "")[-600:]}
            records.append(record)
            if outcome in ("invalid", "crash", "hang"):
                findings.append(record)
            shutil.rmtree(os.path.join(work, f"case{index}"), ignore_errors=True)
            index += 1
    finally:
        runner.stop()
        shutil.rmtree(work, ignore_errors=True)
    elapsed = time.monotonic() - start
    print(f"fuzz_cli: seed {args.seed}, {index} cases in {elapsed:.1f} s: " +
          ", ".join(f"{outcome} {counts[outcome]}" for outcome in OUTCOMES))
    allowed = {name for name in args.allow.split(",") if name}
    failing = [record for record in findings if record["outcome"] not in allowed]
    for record in findings[:40]:
        print(f"  case {record['case']} [{record['outcome']}] {record['input']}: "
              f"{record['message'][:200]} {record['detail'][:300]}")
    if args.json:
        with open(args.json, "w", encoding="utf-8") as stream:
            json.dump({"seed": args.seed, "counts": counts, "cases": records}, stream, indent=1)
    return 1 if failing else 0


if __name__ == "__main__":
    sys.exit(main())

"""Verified, atomic output: a result is either published whole or not at all.

A grid file that is only half written is worse than none: it looks like a result. Every
writer of BlockForge goes through :class:`StagedOutput`:

1. ``StagedOutput(target)`` removes leftovers of interrupted earlier runs for the same
   target (staging folders and unreferenced companion folders of processes that are
   gone) and makes a fresh hidden staging folder beside the target (same file system,
   so renames are atomic).
2. The writer writes into :meth:`StagedOutput.staged`; it checks what it wrote (the VTK
   XML writers report some failures only through error events, and a file size limit or
   a full disk can leave a short file with success returned) and calls
   :func:`sync_file` on each file, so that delayed write errors surface before publishing.
3. :meth:`StagedOutput.publish` moves companion folders (the pieces of a ``.vtm``) to
   *fresh* names beside the target, which nothing references yet, then renames the main
   file over the target: this one rename publishes the new result. Companions of the old
   result are removed only after it.

A kill between any two steps leaves either the old result or the new one, complete, plus
leftovers that the next run for the same target removes. Single-file formats (Plot3D
``.xyz``, CGNS ``.cgns``) use steps 1-3 without companions; a multi-file format whose main
file names its companions (``.vtm`` and its pieces) uses fresh companion names as here.
"""
import errno
import os
import re
import secrets
import shutil
import xml.etree.ElementTree as ElementTree

from . import printable

STAGING_SUFFIX = ".staging"
PIECES_MARK = ".pieces-"


def _companion_stem(name):
    """The target's stem for companion names, with bytes that are not UTF-8 made '_': the
    main file names its companions, and a .vtm must be valid UTF-8 XML to be read."""
    stem = os.path.splitext(name)[0]
    return "".join("_" if "\udc80" <= c <= "\udcff" else c for c in stem)


def _process_alive(pid):
    """Whether another process *pid* runs (this process's own leftovers are stale: one
    process writes one target at a time)."""
    if pid == os.getpid():
        return False
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:
        return True
    return True


def sync_file(path):
    """fsync *path* (a file or a folder): write errors the kernel only reports at
    write-back (a full disk on delayed allocation) are raised here as OSError."""
    fd = os.open(path, os.O_RDONLY)
    try:
        os.fsync(fd)
    finally:
        os.close(fd)


class StagedOutput:
    """Stages the output for *target* beside it and publishes it with one rename.

    Use as a context manager; the staging folder is removed on exit, whatever happens.
    Names used beside ``DIR/NAME``: ``DIR/.NAME.<pid>-<token>.staging/`` (staging) and
    companion folders ``DIR/<stem>.pieces-<pid>-<token>/``.
    """

    def __init__(self, target):
        self.target = os.path.abspath(target)
        self.directory, self.name = os.path.split(self.target)
        self.stem = _companion_stem(self.name)
        self.token = f"{os.getpid()}-{secrets.token_hex(4)}"
        self.staging = os.path.join(self.directory,
                                    f".{self.name}.{self.token}{STAGING_SUFFIX}")
        try:
            os.makedirs(self.directory, exist_ok=True)
            clean_leftovers(self.target)
            os.mkdir(self.staging)
        except OSError as error:
            raise RuntimeError(f"cannot write {printable(self.target)}: "
                               f"{error.strerror or error}") from None
        self._published = []  # fresh companions moved beside the target, for rollback

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        shutil.rmtree(self.staging, ignore_errors=True)
        return False

    def staged(self, relative):
        """Path of *relative* inside the staging folder."""
        return os.path.join(self.staging, relative)

    def fresh_companion_name(self):
        """A companion folder name nobody references yet: ``<stem>.pieces-<pid>-<token>``."""
        return f"{self.stem}{PIECES_MARK}{self.token}"

    def publish(self, staged_main, companions=(), old_companions=()):
        """Moves every staged folder of *companions* (names inside the staging folder) beside
        the target under the same name, then renames *staged_main* over the target (the
        publishing step), then removes *old_companions* (absolute paths: what the old
        result referenced). On an error before the publishing rename, the moved companions
        are removed again and the old result stays as it was."""
        try:
            for name in companions:
                destination = os.path.join(self.directory, name)
                os.rename(self.staged(name), destination)
                self._published.append(destination)
            sync_file(self.directory)
            os.replace(staged_main, self.target)
        except BaseException:
            for destination in self._published:
                shutil.rmtree(destination, ignore_errors=True)
            raise
        sync_file(self.directory)
        for path in old_companions:
            if os.path.isdir(path) and not os.path.islink(path):
                shutil.rmtree(path, ignore_errors=True)


def referenced_folders(vtm_path):
    """The folders directly beside *vtm_path* that its DataSet entries reference (a set of
    absolute paths; empty when the file is missing or unreadable)."""
    folders = set()
    try:
        root = ElementTree.parse(vtm_path).getroot()
    except (OSError, ElementTree.ParseError):
        return folders
    base = os.path.dirname(os.path.abspath(vtm_path))
    for element in root.iter("DataSet"):
        reference = element.get("file")
        if not reference or os.path.isabs(reference):
            continue
        first = os.path.normpath(reference).split(os.sep)[0]
        if first not in ("", ".", "..") and first != os.path.normpath(reference):
            folders.add(os.path.join(base, first))
    return folders


def clean_leftovers(target):
    """Removes what interrupted runs for *target* left beside it: staging folders and
    companion folders (``<stem>.pieces-<pid>-<token>``) of processes that no longer run,
    companions only when the current target does not reference them. Returns the removed
    paths."""
    target = os.path.abspath(target)
    directory, name = os.path.split(target)
    stem = _companion_stem(name)
    staging = re.compile(re.escape(f".{name}.") + r"(\d+)-[0-9a-f]+" + re.escape(STAGING_SUFFIX))
    pieces = re.compile(re.escape(stem + PIECES_MARK) + r"(\d+)-[0-9a-f]+")
    try:
        entries = os.listdir(directory)
    except OSError:
        return []
    in_use = referenced_folders(target)
    removed = []
    for entry in entries:
        match = staging.fullmatch(entry) or pieces.fullmatch(entry)
        path = os.path.join(directory, entry)
        if not match or path in in_use or _process_alive(int(match.group(1))):
            continue
        if os.path.isdir(path) and not os.path.islink(path):
            shutil.rmtree(path, ignore_errors=True)
            removed.append(path)
    return removed


def _path_argument(path):
    from . import _path_argument as convert

    return convert(path)


def _check_piece(path, block):
    """Reads a written piece back: raises RuntimeError unless it is complete and has the
    block's dimensions."""
    from vtkmodules.vtkIOXML import vtkXMLStructuredGridReader

    messages = _Messages()
    reader = vtkXMLStructuredGridReader()
    messages.watch(reader)
    reader.SetFileName(_path_argument(path))
    reader.Update()
    grid = reader.GetOutput()
    if (messages.texts or grid is None
            or grid.GetNumberOfPoints() != block.GetNumberOfPoints()
            or grid.GetNumberOfCells() != block.GetNumberOfCells()
            or grid.GetCellData().GetNumberOfArrays() != block.GetCellData().GetNumberOfArrays()):
        detail = f": {messages.first()}" if messages.texts else ""
        raise RuntimeError(f"{printable(path)} is incomplete after writing{detail}")


class _Messages:
    """Collects the error messages of VTK objects (text that is not UTF-8 is kept readable)."""

    def __init__(self):
        self.texts = []

    def watch(self, vtk_object):
        from vtkmodules.util.misc import calldata_type
        from vtkmodules.util.vtkConstants import VTK_STRING
        from vtkmodules.vtkCommonCore import vtkCommand

        @calldata_type(VTK_STRING)
        def collect(_caller, _event, message):
            self.texts.append(message)

        vtk_object.AddObserver(vtkCommand.ErrorEvent, collect)

    def first(self):
        from . import _message

        return _message(self.texts[0])


class _quiet_vtk:
    """Catches what VTK prints during a write (the piece writers' executives report their
    failures only to the output window, as pages of pipeline detail): the caller turns it
    into one clear error."""

    def __enter__(self):
        from vtkmodules.vtkCommonCore import vtkLogger, vtkOutputWindow, vtkStringOutputWindow

        self.previous = vtkOutputWindow.GetInstance()
        self.window = vtkStringOutputWindow()
        vtkOutputWindow.SetInstance(self.window)
        # VTK's logger prints errors to stderr itself, besides the output window
        self.verbosity = vtkLogger.GetCurrentVerbosityCutoff()
        vtkLogger.SetStderrVerbosity(vtkLogger.VERBOSITY_OFF)
        return self.window

    def __exit__(self, *exc):
        from vtkmodules.vtkCommonCore import vtkLogger, vtkOutputWindow

        vtkLogger.SetStderrVerbosity(vtkLogger.ConvertToVerbosity(self.verbosity))
        vtkOutputWindow.SetInstance(self.previous)
        return False


def write_failure_reason(folder):
    """Why writing into *folder* most likely failed when the writer said only that it
    failed (VTK's XML writers): its file system is full, or a file reached the process's
    file-size limit; None when neither."""
    import resource

    try:
        if os.statvfs(folder).f_bavail == 0:
            return os.strerror(errno.ENOSPC)
    except OSError:
        return None
    limit = resource.getrlimit(resource.RLIMIT_FSIZE)[0]
    if limit != resource.RLIM_INFINITY:
        for root, _, names in os.walk(folder):
            for name in names:
                try:
                    if os.path.getsize(os.path.join(root, name)) >= limit:
                        return os.strerror(errno.EFBIG)
                except OSError:
                    pass
    return None


def _leaves(multiblock):
    from vtkmodules.vtkCommonDataModel import vtkDataObjectTreeIterator

    iterator = vtkDataObjectTreeIterator()
    iterator.SetDataSet(multiblock)
    iterator.SkipEmptyNodesOn()
    iterator.VisitOnlyLeavesOn()
    iterator.InitTraversal()
    while not iterator.IsDoneWithTraversal():
        yield iterator.GetCurrentDataObject()
        iterator.GoToNextItem()


def write_vtm(data_object, path, compress=False):
    """Writes *data_object* (a vtkMultiBlockDataSet of structured grids) as the ``.vtm``
    *path* plus a folder of pieces ``<stem>.pieces-<pid>-<token>/`` beside it, verified and
    published with one rename (see the module documentation); the pieces folder of the
    grid that was there before is removed after. The pieces are raw binary unless
    *compress* (zlib, VTK's default: about 3 times smaller on the passage grids but, at 1
    million cells, most of the writing time). :raises RuntimeError: when writing or the
    check of what was written fails (the older grid is then left as it was)."""
    from vtkmodules.vtkIOXML import vtkXMLMultiBlockDataWriter

    path = os.path.abspath(path)
    with StagedOutput(path) as output:
        pieces = output.fresh_companion_name()
        staged_main = output.staged(pieces + ".vtm")  # the writer names the folder by the file
        messages = _Messages()
        writer = vtkXMLMultiBlockDataWriter()
        messages.watch(writer)
        writer.SetInputData(data_object)
        writer.SetFileName(_path_argument(staged_main))
        writer.SetDataModeToAppended()
        writer.EncodeAppendedDataOff()
        if compress:
            writer.SetCompressorTypeToZLib()
        else:
            writer.SetCompressorTypeToNone()
        with _quiet_vtk() as noise:
            written = writer.Write()
        if not written or messages.texts or writer.GetErrorCode() or noise.GetOutput():
            detail = messages.first() if messages.texts else "the VTK writer failed"
            reason = write_failure_reason(output.staging)
            raise RuntimeError(f"could not write {printable(path)}: {detail} (" +
                               (reason if reason else "check the free space, the file size "
                                "limit and the permissions there") + ")")
        # What was written: the .vtm must be complete XML naming one piece per non-empty
        # block, each piece complete and the size of its block.
        staged_pieces = output.staged(pieces)
        blocks = list(_leaves(data_object))
        references = []
        try:
            for element in ElementTree.parse(staged_main).getroot().iter("DataSet"):
                if element.get("file"):
                    references.append(element.get("file"))
        except ElementTree.ParseError as error:
            raise RuntimeError(f"could not write {printable(path)}: the written .vtm is "
                               f"incomplete ({error})") from None
        if len(references) != len(blocks):
            raise RuntimeError(f"could not write {printable(path)}: {len(references)} of "
                               f"{len(blocks)} pieces written")
        for reference, block in zip(references, blocks):
            piece = os.path.join(output.staging, reference)
            if os.path.dirname(os.path.normpath(piece)) != staged_pieces:
                raise RuntimeError(f"could not write {printable(path)}: unexpected piece "
                                   f"{printable(reference)}")
            _check_piece(piece, block)
            sync_file(piece)
        sync_file(staged_main)
        if os.path.isdir(staged_pieces):
            sync_file(staged_pieces)
        old = [folder for folder in referenced_folders(path)
               if os.path.basename(folder) == output.stem
               or os.path.basename(folder).startswith(output.stem + PIECES_MARK)]
        output.publish(staged_main, [pieces] if os.path.isdir(staged_pieces) else [], old)

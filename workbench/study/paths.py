"""Output paths checked before any work starts, so that no result is lost at the end.

Each check raises ParameterError naming the option as the user wrote it,
the path and what is wrong: a missing or non-directory parent, a directory
where a file goes, a file where a folder goes, a name longer than the file
system allows, no write permission.
"""
from __future__ import annotations

import contextlib
import os
import shutil
import tempfile
from pathlib import Path

from ..model.params import ParameterError


def _name_max(folder: Path) -> int:
    try:
        return os.pathconf(folder, "PC_NAME_MAX")
    except (OSError, ValueError):
        return 255


def _existing_ancestor(path: Path) -> Path:
    for parent in [path, *path.parents]:
        if os.path.lexists(parent):
            return parent
    return Path(".")


def check_output_dir(option: str, folder: str | os.PathLike) -> Path:
    """``folder`` can be created (or is) a writable directory."""
    path = Path(folder)
    if str(folder) == "":
        raise ParameterError(f"{option} is empty: give a folder")
    anc = _existing_ancestor(path)
    if not anc.is_dir():
        what = "is" if anc == path else "is inside"
        raise ParameterError(f"{option} {folder}: {what} {anc}, which is a file, not a folder")
    for part in path.relative_to(anc).parts if anc != Path(".") else path.parts:
        if len(part.encode()) > _name_max(anc):
            raise ParameterError(f"{option} {folder}: the name {part[:40]!r}... is longer than "
                                 f"the file system allows ({_name_max(anc)} bytes)")
    if not os.access(anc, os.W_OK | os.X_OK):
        raise ParameterError(f"{option} {folder}: {anc} is not writable")
    return path


def check_output_file(option: str, file: str | os.PathLike, suffixes=()) -> Path:
    """``file`` can be written: its folder exists, it is not a folder, its suffix is known."""
    path = Path(file)
    if os.path.isdir(path):              # False, not OSError, for a name too long
        raise ParameterError(f"{option} {file}: is a folder; give a file name")
    if suffixes and path.suffix.lower() not in suffixes:
        raise ParameterError(f"{option} {file}: the suffix must be one of {', '.join(suffixes)}")
    parent = path.parent
    if not os.path.isdir(parent):
        anc = _existing_ancestor(parent)
        problem = "does not exist" if anc.is_dir() else f"is inside {anc}, which is a file"
        raise ParameterError(f"{option} {file}: the folder {parent} {problem}")
    if len(path.name.encode()) > _name_max(parent):
        raise ParameterError(f"{option} {file}: the name is longer than the file system allows "
                             f"({_name_max(parent)} bytes)")
    target = path if path.exists() else parent
    if not os.access(target, os.W_OK):
        raise ParameterError(f"{option} {file}: {target} is not writable")
    return path


@contextlib.contextmanager
def staged_output(folder: Path):
    """A scratch folder beside ``folder`` to write the outputs into; on success its files
    move into ``folder`` (created then), on an error it is removed: a failed command leaves
    no half-written folder and replaces none of the files already there."""
    folder = Path(folder)
    folder.parent.mkdir(parents=True, exist_ok=True)
    scratch = Path(tempfile.mkdtemp(prefix=f".{folder.name}.partial-", dir=folder.parent))
    try:
        yield scratch
        folder.mkdir(exist_ok=True)
        for item in sorted(scratch.iterdir()):
            os.replace(item, folder / item.name)
    finally:
        shutil.rmtree(scratch, ignore_errors=True)

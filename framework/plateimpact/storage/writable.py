"""What makes an archive writable, checked before any work: names that fit, no symlink
where the archive keeps its own files, a lock that is its own, an index that is whole,
of this format version and reaching no other file (docs/archive.md, "Safety")."""

from __future__ import annotations

import datetime as dt
import os
import stat
from pathlib import Path

from ..base.errors import ArchiveError
from ..base.untrusted import printable
from . import confined, records
from .append import FORMAT_VERSION
from .confined import check_lengths, shown_version
from .output import TEMPORARY_EXTRA, unwritable
from .reader import ArchiveFiles


def check_writable(archive: ArchiveFiles, study: str | None = None) -> None:
    """Refuse what an append to ``archive`` would refuse after a long run
    (:meth:`plateimpact.storage.archive.Archive.check_writable`)."""
    directory = archive.real.parent
    if not archive.named:
        raise ArchiveError(f"archive {archive.path!s}: give an archive file name")
    check_lengths(archive.path, archive.real, f"archive {printable(archive.path, 80)}")
    if archive.real.is_dir():
        raise ArchiveError(f"archive {archive.path!s}: give an archive file name")
    if not directory.is_dir():
        raise ArchiveError(f"archive {archive.path}: directory {directory} does not exist")
    if not os.access(directory, os.W_OK | os.X_OK):
        raise ArchiveError(
            f"archive {archive.path}: directory {directory} is {unwritable(directory)}"
        )
    if os.path.lexists(archive.data):
        with confined.directory(archive.data, f"archive {archive.path}: its data directory"):
            pass  # a symlink, not a directory: refused
        if not os.access(archive.data, os.W_OK | os.X_OK):
            why = unwritable(archive.data)
            raise ArchiveError(
                f"archive {archive.path}: its data directory {archive.data} is {why}"
            )
    if os.path.lexists(archive.lock_path):
        check_lock(archive.lock_path, archive.path)
    if study is not None:
        records.check_study_name(study, archive.path)
    if archive._exists():
        mode = os.stat(archive.real).st_mode
        if not stat.S_ISREG(mode):
            raise ArchiveError(f"archive {archive.path} is not a regular file")
        if not mode & (stat.S_IWUSR | stat.S_IWGRP | stat.S_IWOTH):
            raise ArchiveError(f"archive {archive.path} is read-only; refusing to append to it")
        with archive._open() as f:  # damaged, not an archive, another version: refused now
            version = f.attrs.get("format_version")
            records.study_names(f)  # a group for each study, and for its runs
            records.record_names(f)
            if version == FORMAT_VERSION and study is not None and study in f:
                with archive._linked(f, f"{study}/scenes"):
                    pass  # its scenes are there, in this directory (a renamed archive too)
        if version != FORMAT_VERSION:
            raise ArchiveError(
                f"archive {archive.path} has format version {shown_version(version)}, which "
                "this plateimpact reads but does not append to; `plateimpact upgrade "
                f"{archive.path}` rewrites it as version {FORMAT_VERSION}"
            )


def side_archive(real: Path, tag: str) -> Path:
    """Where a writer that cannot wait saves its run: ``STEM.TAG.TIME.SUFFIX`` beside the
    archive, the tag cut so that the name and its temporaries fit NAME_MAX."""
    time = f"{dt.datetime.now(dt.UTC):%Y%m%dT%H%M%S%f}"
    room = 255 - len(os.fsencode(f"{real.stem}..{time}{real.suffix}")) - TEMPORARY_EXTRA
    cut = os.fsencode(tag)[: max(room, 0)].decode(errors="ignore")
    return real.with_name(f"{real.stem}.{cut}.{time}{real.suffix}")


def check_lock(lock: Path, path: Path) -> None:
    """Refuse a lock file that is a symlink or not a regular file with one link (one that
    came with the archive from someone else), before any work."""
    status = os.lstat(lock)
    if stat.S_ISLNK(status.st_mode):
        raise ArchiveError(
            f"archive {path}: its lock {lock} is a symbolic link; refusing to follow it "
            "(remove it: an archive's lock is an ordinary file of its own)"
        )
    if not stat.S_ISREG(status.st_mode) or status.st_nlink != 1:
        what = (
            "not a regular file"
            if not stat.S_ISREG(status.st_mode)
            else ("a second name (hard link) of another file")
        )
        raise ArchiveError(
            f"archive {path}: its lock {lock} is {what}; refusing to write it (remove it: an "
            "archive's lock is an ordinary file of its own)"
        )

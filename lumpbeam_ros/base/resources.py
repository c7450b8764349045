"""Where the package's own files (the default ``config/`` YAMLs) are found.

The same lookup serves a colcon install (the ament share directory), a pip install (the
``share/`` data_files under the interpreter prefix) and a source checkout (editable install).
"""

from __future__ import annotations

import sys
from pathlib import Path

PACKAGE = 'lumpbeam_ros'


def _candidate_share_dirs() -> list[Path]:
    candidates = [Path(__file__).resolve().parents[2]]  # a source checkout
    try:
        from ament_index_python.packages import PackageNotFoundError, get_package_share_directory
    except ImportError:
        pass
    else:
        try:
            candidates.append(Path(get_package_share_directory(PACKAGE)))
        except (PackageNotFoundError, LookupError, OSError, ValueError):
            pass  # not in an ament workspace, or AMENT_PREFIX_PATH is unset
    candidates.append(Path(sys.prefix) / 'share' / PACKAGE)
    return candidates


def share_dir() -> Path:
    """The package's share folder, the one holding ``config/`` (and ``launch/``).

    Raises:
        FileNotFoundError: The package is installed without its ``config/`` files.
    """
    for share in _candidate_share_dirs():
        if (share / 'config').is_dir():
            return share
    raise FileNotFoundError(f'{PACKAGE}: the share folder (config/, launch/) is not installed')


def packaged(path: str | Path) -> Path:
    """A file given by path, or the installed package's own of that relative path.

    The docs name the package's files by their place in the repository (``config/...``,
    ``launch/...``, ``examples/...``); after a wheel or colcon install they are in the share
    folder instead, and the same words find them there.

    Args:
        path: A file, as the user gave it.

    Returns:
        ``path`` when it exists, or is absolute; else the share folder's file of that relative
        path when there is one; else ``path`` (for the caller's "no such file").
    """
    given = Path(path)
    try:
        if given.exists() or given.is_absolute():
            return given
        for share in _candidate_share_dirs():
            if (share / given).is_file():
                return share / given
    except OSError:
        pass  # a name the system refuses (too long): the caller's read says so
    return given


def config_path(name: str) -> Path:
    """Returns the path of a default configuration file.

    Args:
        name: File name under ``config/``, e.g. ``'paper_beam.yaml'``.

    Returns:
        The first existing candidate.

    Raises:
        FileNotFoundError: The package is installed without its ``config/`` files.
    """
    for share in _candidate_share_dirs():
        path = share / 'config' / name
        if path.is_file():
            return path
    raise FileNotFoundError(f'{PACKAGE}: default config {name!r} is not installed')


def large_frames_profile() -> Path:
    """The Fast DDS profile for camera frames of a megabyte and more.

    Point ``FASTRTPS_DEFAULT_PROFILES_FILE`` at it: it gives the shared-memory transport a
    segment large enough for whole frames; with the default transport most 1 MB frames at
    180 fps are lost between processes.
    """
    return Path(__file__).resolve().parent / 'data' / 'fastdds_large_frames.xml'

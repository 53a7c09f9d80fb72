"""rtweekend's version: pyproject.toml's, the one place it is written.

From a source checkout, pyproject.toml beside the package is read (it is what
this code is); an installed copy has no such file and reads the metadata that
pip wrote from the same pyproject.toml.
"""
import tomllib
from functools import cache
from importlib import metadata
from pathlib import Path

PYPROJECT = Path(__file__).resolve().parent.parent / "pyproject.toml"


@cache
def version():
    try:
        project = tomllib.loads(PYPROJECT.read_text(encoding="utf-8"))["project"]
        if project.get("name") == "rtweekend":
            return project["version"]
    except (OSError, KeyError, tomllib.TOMLDecodeError):
        pass
    try:
        return metadata.version("rtweekend")
    except metadata.PackageNotFoundError:
        return "unknown"

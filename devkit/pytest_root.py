"""pytest plugin (``-p devkit.pytest_root`` in pyproject.toml): collect the repository top as a plain folder.

The top folder is the extension's package: its ``__init__.py`` does a relative import. pytest makes a
folder with ``__init__.py`` a test package and imports that file as a module; when the checkout's folder
name is not a Python identifier (``wt-synth``, ``ElliMann-main``) the import fails and every test errors.
"""

import pytest


def pytest_collect_directory(path, parent):
    if path == parent.config.rootpath:
        return pytest.Dir.from_parent(parent, path=path)
    return None

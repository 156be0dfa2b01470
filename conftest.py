"""pytest: the repository root is the extension's package folder, not a test package."""

import pytest


class _RootIsNotATestPackage:
    """The root ``__init__.py`` is the extension entry point (relative imports). Collected as a
    Package, pytest imports it under the checkout folder's name, which fails when that name is not
    an identifier (e.g. 'ElliMann-main'). As a plain directory it is never imported."""

    @pytest.hookimpl(tryfirst=True)
    def pytest_collect_directory(self, path, parent):
        if path == parent.config.rootpath:
            return pytest.Dir.from_parent(parent, path=path)
        return None


def pytest_configure(config):
    # Registered as a global plugin: a conftest hook would only see directories below the root.
    config.pluginmanager.register(_RootIsNotATestPackage(), "ellimann-root-dir")

"""The checkout is itself the package ``rpdrill`` (its ``__init__.py`` is the library's front door), not a
package of tests: pytest collects its folder as a plain directory, so that the tests run in a checkout
of any folder name (``rpdrill-main``, ``rpdrill-1.0``), not only in one whose name is a Python name."""

from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent


class _CheckoutFolder:
    @pytest.hookimpl(tryfirst=True)
    def pytest_collect_directory(self, path: Path, parent: pytest.Collector) -> pytest.Collector | None:
        return pytest.Dir.from_parent(parent, path=path) if path == ROOT else None


def pytest_configure(config: pytest.Config) -> None:
    config.pluginmanager.register(_CheckoutFolder(), "rpdrill-checkout-folder")

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


def pytest_collection_modifyitems(config: pytest.Config, items: list[pytest.Item]) -> None:
    """The long-running checks (marked ``slow``) first: pytest-xdist hands the tests out in this order, so
    the longest start while the short ones fill the other core, instead of one core finishing them alone
    at the end (the order within each group is kept, so a module's shared fixtures are still computed once
    per worker)."""
    items.sort(key=lambda item: item.get_closest_marker("slow") is None)

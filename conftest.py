"""The checkout is itself the package ``rpdrill`` (its ``__init__.py`` is the library's front door), not a
package of tests: pytest collects its folder as a plain directory, so that the tests run in a checkout
of any folder name (``rpdrill-main``, ``rpdrill-1.0``), not only in one whose name is a Python name."""

import subprocess
import sys
import warnings
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent


class _CheckoutFolder:
    @pytest.hookimpl(tryfirst=True)
    def pytest_collect_directory(self, path: Path, parent: pytest.Collector) -> pytest.Collector | None:
        return pytest.Dir.from_parent(parent, path=path) if path == ROOT else None


def pytest_configure(config: pytest.Config) -> None:
    config.pluginmanager.register(_CheckoutFolder(), "rpdrill-checkout-folder")


def _module_fixtures(item: pytest.Item) -> bool:
    """Whether ``item`` uses a module-scoped fixture (a result computed once and asserted on many times)."""
    definitions = getattr(getattr(item, "_fixtureinfo", None), "name2fixturedefs", {})
    return any(defs and defs[-1].scope == "module" for defs in definitions.values())


# numba's kernels (compiled at their first call, then cached on disk beside their modules: ``cache=True``) and a run
# that compiles each set: the exact formulation with its periodic orbit's monodromy, and the wave rods
KERNEL_MODULES = ("models/solvers/exact_kernels", "models/solvers/exact_power_kernels", "models/waves/kernels",
                  "models/steady/monodromy_kernel")
KERNEL_RUNS = (
    ('import rpdrill; rpdrill.simulate(rpdrill.load_scene("paper_base").with_({"solver.end_time_s": 0.25, '
    '"solver.steady_state": "periodic"}), formulation="exact")'),
    ('import rpdrill; rpdrill.simulate(rpdrill.load_scene("top_hammer_waves").with_({"solver.end_time_s": 0.02, '
    '"metrics.transient_blows": 0, "metrics.block_blows": 1}), formulation="exact")'),
)


def _kernels_cached() -> bool:
    return all(any((ROOT / module).parent.glob(f"__pycache__/{Path(module).name}.*.nbi")) for module in KERNEL_MODULES)


def pytest_sessionstart(session: pytest.Session) -> None:
    """On the controller of pytest-xdist workers, before they start (its own session start runs last): a checkout
    whose numba kernels are not compiled yet (a fresh clone) compiles them once, the two sets side by side in
    processes of their own, instead of once in each worker that first needs them (both did, in the suite's first
    tests: 436.0 CPU s and 235.57 s for the suite against 395.5 and 214.91 with the kernels cached, `python
    benchmarks/bench_tests.py`; docs/performance.md, "Test suite")."""
    if hasattr(session.config, "workerinput") or not getattr(session.config.option, "numprocesses", 0):
        return
    if _kernels_cached():
        return
    runs = [subprocess.Popen([sys.executable, "-c", code], cwd=ROOT, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
            for code in KERNEL_RUNS]
    for run in runs:  # a run that fails, or hangs, leaves its kernels to the tests, whose failures say why
        try:
            run.wait(timeout=600)
        except subprocess.TimeoutExpired:
            run.kill()


@pytest.hookimpl(tryfirst=True)
def pytest_collection_modifyitems(config: pytest.Config, items: list[pytest.Item]) -> None:
    """The long-running checks (marked ``slow``) first, and every module with a module-scoped fixture one
    group (pyproject.toml: ``--dist loadgroup --no-loadscope-reorder``).

    pytest-xdist hands the tests out in this order, so the longest start while the short ones fill the other
    core, instead of one core finishing them alone at the end; a module's shared results are computed once,
    on the one worker that runs its tests, not once on each worker that gets some of them (the order within
    each group is kept)."""
    items.sort(key=lambda item: item.get_closest_marker("slow") is None)
    for item in items:
        if _module_fixtures(item):
            item.add_marker(pytest.mark.xdist_group(item.module.__name__ if item.module else item.nodeid))


@pytest.hookimpl(trylast=True)
def pytest_collection_finish(session: pytest.Session) -> None:
    """On a pytest-xdist worker of ``--dist loadgroup``: a warning when a grouped test's node id lacks its group
    (pytest-xdist issue 1386, pytest 9.2): the groups are then ignored, silently, and every module's shared
    results computed on each worker that gets some of its tests."""
    if not getattr(session.config.option, "loadgroup", False):
        return
    lost = [item.nodeid for item in session.items if item.get_closest_marker("xdist_group") and "@" not in item.nodeid]
    if lost:
        warnings.warn(f"pytest-xdist --dist loadgroup groups nothing with this pytest ({len(lost)} grouped tests, "
                      f"e.g. {lost[0]}, without their group): a module's shared results are computed on every "
                      "worker (pytest-xdist issue 1386; pyproject.toml pins pytest below 9.2)", stacklevel=1)

"""What surrounds an Exudyn solve: what Exudyn prints, as one warning a line (the command line shows
each as ``rpdrill: warning: ...``), Python's cyclic garbage collector paused while it runs, and the
per-step functions that watch it (the guard of an automatic step, progress reports), the one
pre-step function that runs them all in order, and Exudyn's simulation settings of a run.

And before and while it runs, the user's code kept the user's: the scene's extensions
(models.definition.extensions) called on the built model, which is then prepared with what they added
(models.solvers.exudyn_user_items). What the user's code does wrong there ends the run as a failed run,
``SimulationFailed`` (exit status 1 on the command line, a study's point ``failed``), with one message naming
the scene, the extension's key (``extensions.NAME``), its name in the scene and the user's exception with the
file and line of the user's code (models.definition.own_code.failure): the function raises, or calls
``sys.exit`` (which would end a command with status 0 and no word); what it added cannot be prepared (a
spring of NaN stiffness) or solved (a mass Exudyn cannot invert: :func:`solver_errors`). A body or connector
it names that the model lacks (``model.bodies["colar"]``) is a ``KeyError`` listing those there are
(:class:`NamedItems`)."""

from __future__ import annotations

import contextlib
import gc
import io
import re
import sys
import warnings
from collections.abc import Callable, Iterator, Sequence
from typing import TYPE_CHECKING, Any

from ...rocklaw.exudyn_module import exu
from ..definition.formulations import AUTOMATIC_STEP_SOLVERS
from ..definition.own_code import failure
from ..definition.validation import InputError
from ..evaluation.stability import SimulationFailed
from .exudyn_user_items import follow_extension_coordinates

if TYPE_CHECKING:
    from .simulation import Simulation

SOLVER_TYPES = {  # the scene's solver.type as Exudyn's DynamicSolverType
    "rk67": exu.DynamicSolverType.RK67,
    "rk44": exu.DynamicSolverType.RK44,
    "rk33": exu.DynamicSolverType.RK33,
    "explicit_midpoint": exu.DynamicSolverType.ExplicitMidpoint,
    "explicit_euler": exu.DynamicSolverType.ExplicitEuler,
    "generalized_alpha": exu.DynamicSolverType.GeneralizedAlpha,
    "trapezoidal_index2": exu.DynamicSolverType.TrapezoidalIndex2,
    "dopri5": exu.DynamicSolverType.DOPRI5,
    "ode23": exu.DynamicSolverType.ODE23,
}


@contextlib.contextmanager
def no_cyclic_gc() -> Iterator[None]:
    """Python's cyclic garbage collector paused: the per-step hooks allocate small objects without
    cycles (freed by reference counting), and the collections they would trigger cost ~5 % of a run."""
    enabled = gc.isenabled()
    gc.disable()
    try:
        yield
    finally:
        if enabled:
            gc.enable()


class ExudynMessage(UserWarning):
    """What Exudyn printed during a run (its warnings), issued as a warning instead: one a distinct line,
    naming the scene.

    Parameters
    ----------
    *args
        The line, its scene named.

    Examples
    --------
    >>> import rpdrill
    >>> rpdrill.ExudynMessage("scene 'paper_base': Exudyn: ...").args[0].startswith("scene")
    True
    """


EXUDYN_PREFIX = re.compile(r"^\s*Python WARNING \[file '[^']*', line \d+\]:\s*")


@contextlib.contextmanager
def exudyn_messages_as_warnings(name: str) -> Iterator[None]:
    """What Exudyn prints while the block runs (it prints through sys.stdout) comes out as one
    :class:`ExudynMessage` warning per distinct line, without Exudyn's file and line prefix; nothing when
    a Ctrl-C stopped the run (Exudyn's "DYNAMIC SOLVER FAILED" lines then tell of the stop itself)."""
    printed = io.StringIO()
    try:
        with contextlib.redirect_stdout(printed):
            yield
    finally:
        stopped = interrupt_behind(sys.exc_info()[1]) is not None
        lines = [] if stopped else [EXUDYN_PREFIX.sub("", line).strip() for line in printed.getvalue().splitlines()]
        for line in dict.fromkeys(line for line in lines if line):
            warnings.warn(f"scene '{name}': Exudyn: {line}", ExudynMessage, stacklevel=3)


def interrupt_behind(error: BaseException | None) -> KeyboardInterrupt | None:
    """The KeyboardInterrupt ``error`` is, or was raised on (Exudyn's ModelError when a Ctrl-C reached a Python
    function it called, and what the run made of that error); None when there is none."""
    seen: set[int] = set()
    while error is not None and id(error) not in seen:
        if isinstance(error, KeyboardInterrupt):
            return error
        seen.add(id(error))
        error = error.__cause__ or error.__context__
    return None


class MinimumStepGuard:
    """Stops an automatic-step run whose step fell to Exudyn's minimum (Exudyn would go on with
    errors beyond the tolerance, or crawl for hours at that step) and remembers when. The step
    is the solver's own (rejected attempts also call the pre-step function)."""

    def __init__(self, minimum_step_s: float) -> None:
        self.minimum_step_s, self.reached_at_s = minimum_step_s, None

    def __call__(self, mbs: Any, t: float) -> bool:
        if mbs.sys["dynamicSolver"].it.currentStepSize <= self.minimum_step_s * (1 + 1e-6):
            self.reached_at_s = t
            return False
        return True

    def check(self, name: str, solver: Any) -> None:
        """SimulationFailed, with a remedy, when the run of scene ``name`` reached the minimum step."""
        if self.reached_at_s is not None:
            raise SimulationFailed(
                f"scene '{name}': solver {solver.type} with relative_tolerance {solver.relative_tolerance:g} reached "
                f"the minimum step {self.minimum_step_s:g} s at t = {self.reached_at_s:.6g} s; try relative_tolerance "
                f"{solver.relative_tolerance * 100:g} or a fixed-step preset (solver: {{preset: standard}})")


def progress_reporter(end_time_s: float, progress: Callable[[float], None]) -> Callable[[Any, float], bool]:
    """A pre-step function calling ``progress(t)`` about 100 times over the run."""
    every = end_time_s / 100
    next_report = [every]

    def report(mbs: Any, t: float) -> bool:
        if t >= next_report[0]:
            next_report[0] += every
            progress(t)
        return True
    return report


def pre_step(actions: Sequence[Callable[[Any, float], bool]]) -> Callable[[Any, float], bool] | None:
    """One Exudyn pre-step function running ``actions`` in order (the one action itself when there is
    one, None when there are none); a False stops the run."""
    if len(actions) <= 1:
        return actions[0] if actions else None
    actions = tuple(actions)

    def run_all(mbs: Any, t: float) -> bool:
        return all(action(mbs, t) for action in actions)
    return run_all


def replaced_pre_step(mbs: Any, installed: Any) -> dict[str, Any] | None:
    """Exudyn's record of the pre-step function on ``mbs`` when it is not ``installed`` (one a user set with
    ``mbs.SetPreStepUserFunction``), else None."""
    current = mbs.GetPreStepUserFunction()
    function = current.get("function") if isinstance(current, dict) else None
    return None if function is None or function is installed else current


def simulation_settings(simulation: Simulation) -> Any:
    """Exudyn's simulation settings of a prepared run (its solver, step, tolerances, sensor storage)."""
    solver = simulation.settings
    settings = exu.SimulationSettings()
    integration = settings.timeIntegration
    integration.endTime = solver.end_time_s
    set_step(settings, solver)
    integration.verboseMode = 0
    integration.generalizedAlpha.spectralRadius = solver.spectral_radius
    integration.newton.useModifiedNewton = True
    if solver.type in AUTOMATIC_STEP_SOLVERS:
        integration.automaticStepSize = True
        integration.relativeTolerance = solver.relative_tolerance
        integration.absoluteTolerance = solver.absolute_tolerance
    else:
        integration.automaticStepSize = False
        integration.adaptiveStep = False
    # the explicit solvers' extra right-hand side per step computes accelerations for output only (none
    # is stored; the states are bitwise the same without it, and a rk44 step costs ~12 % less)
    integration.explicit.computeEndOfStepAccelerations = False
    settings.show.statistics = False
    settings.solution.file.write = False
    # energies are integrated over every step; otherwise store only at the output interval
    settings.solution.sensors.writePeriod = 0.0 if "energy" in simulation.needed_data else solver.output_interval_s
    return settings


def set_step(settings: Any, solver: Any) -> None:
    """Exudyn's settings at the step of the run's ``solver`` settings (an automatic step: its first, a tenth)."""
    integration = settings.timeIntegration
    integration.numberOfSteps = round(solver.end_time_s / solver.step_s)
    integration.initialStepSize = solver.step_s / 10


class UnknownName(KeyError):
    """A name a built model does not have; its message lists the names there are."""

    def __str__(self) -> str:
        return str(self.args[0])


class NamedItems(dict):
    """A built model's bodies or connectors by name (``model.bodies[name]``); a name it does not have is a
    :class:`UnknownName` that lists them."""

    def __init__(self, kind: str, items: dict[str, Any]) -> None:
        super().__init__(items)
        self.kind = kind

    def __missing__(self, name: object) -> Any:
        raise UnknownName(f"the built model has no {self.kind} {name!r}; its {self.kind} names: {', '.join(self)}")

    def __reduce__(self) -> tuple[Any, ...]:
        return NamedItems, (self.kind, dict(self))


def apply_extensions(model: Any) -> None:
    """The scene's extensions applied to the built ``model`` in their order, which is then prepared (the
    coordinates they add followed where a steady-state run asks); SimulationFailed naming the extension and
    the user's error (module doc)."""
    scene = model.simulation.scene
    for name, extension in (scene.extensions or {}).items():
        try:
            extension.apply(model)
        except (Exception, SystemExit) as error:  # noqa: BLE001 - the user's code: its error is the user's
            path = extension.found.import_path
            raise SimulationFailed(f"scene '{scene.name}': extensions.{name} ({extension.function}) failed on the "
                                   f"built model: {failure(error, path.partition(':')[0])}") from None
    if not scene.extensions:
        follow_extension_coordinates(model)
        return
    try:
        follow_extension_coordinates(model)  # model.prepare(), the coordinates a steady-state run follows with it
    except InputError:  # a scene its extensions make that cannot run as given (a start, a solver): bad input
        raise
    except (ValueError, exu.ExudynError) as error:
        raise SimulationFailed(f"scene '{scene.name}': the model with {_named(scene)} cannot be prepared: "
                               f"{type(error).__name__}: {error}") from None


def _named(scene: Any) -> str:
    return ", ".join(f"extensions.{name} ({extension.function})" for name, extension in scene.extensions.items())


@contextlib.contextmanager
def solver_errors(model: Any) -> Iterator[None]:
    """Exudyn's solver refusing the system (a mass matrix it cannot invert, a constraint its solver does not
    take) as a failed run: SimulationFailed naming the scene, and the extensions or items of one's own
    that the system holds beside the drill. A Ctrl-C during the solve stays the KeyboardInterrupt it was
    (Exudyn wraps it in its ModelError when it reaches a Python function the solver calls)."""
    try:
        yield
    except exu.ExudynError as error:
        interrupt = interrupt_behind(error)
        if interrupt is not None:  # a Ctrl-C reached a Python function Exudyn called: a stop, not a failed run
            raise interrupt from None
        scene = model.simulation.scene
        own = _named(scene) if scene.extensions else \
            "items added to the built model" if model.user_items().keys() - {"sensors"} else None
        raise SimulationFailed(f"scene '{scene.name}': Exudyn's solver stopped: {type(error).__name__}: {error}"
                               + (f" (the system holds {own})" if own else "")) from None

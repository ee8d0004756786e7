"""A scene is data: it runs no code unless the user allows it (an installed package's entry point, or a module
allowed for the run), and the user's own code's errors are the user's (models.definition.own_code).

Each finding of the issue is a test here, through the command line (``main`` in this process) or the public
API: a module imported while a scene was read, ``os:spawnvp`` run by a study's planning and workers,
``subprocess:Popen`` constructed as a rock law; a user module that does not parse or raises on import, an
extension that raises, adds a NaN spring or a mass Exudyn refuses, calls ``sys.exit``, or names a body the
model lacks; a rock law whose constructor raises. The user's code is written into a temporary folder on
``sys.path`` by each test (forked workers inherit it). Two are unit tests (UNITS): a prepared run's pickled copy
runs its extension, and the registered names are read once per ``sys.path``."""

from __future__ import annotations

import csv
import importlib.metadata
import json
import pickle
import sys
import textwrap
from pathlib import Path

import pytest
import yaml
from commands import main
from scenes import scene_dict

import rpdrill
from rpdrill.models.definition.own_code import registered
from rpdrill.models.runs.scene_run import run as run_simulation
from rpdrill.models.solvers.simulation import prepare

# The registered names' lookup, and a prepared run pickled as a worker's copy and run.
UNITS = ("rpdrill.models.definition.own_code", "rpdrill.models.runs.scene_run", "rpdrill.models.solvers.simulation")

ROOT = Path(__file__).resolve().parents[1]
SHORT = {"solver.end_time_s": 0.08, "metrics.transient_blows": 1, "metrics.block_blows": 3}
MODULES = ("my_rig", "my_rigx", "rig_pkg", "canary", "rigdist_mod", "needs_dep", "missing_rig", "broken")
JENKINS = {"stiffness_n_per_m": 5.0e8, "damping_n_s_per_m": 1.98e3, "threshold_n": 138.0e3}

# The rig of the tests' user: marked extensions (a counted one, a clamp, ones that fail in every way the
# issue lists), an unmarked function, rock laws (one that raises in its constructor, one in its force).
RIG = '''
import os
import sys
from dataclasses import dataclass
from typing import ClassVar

from exudyn.itemInterface import MarkerNodeCoordinate, Node1D, ObjectConnectorCoordinateSpringDamper, ObjectMass1D

import rpdrill
from rpdrill.rocklaw import JenkinsRock

CALLS = os.path.join(os.path.dirname(__file__), "calls.txt")


@rpdrill.extension
def counted(model, mass_kg: float = 1.0):
    with open(CALLS, "a") as calls:
        calls.write(f"{os.getpid()}\\n")


def _mass(model, mass_kg, stiffness_n_per_m=1.0e8, body="collar"):
    node = model.mbs.AddNode(Node1D(referenceCoordinates=[0.0], initialCoordinates=[0.0], initialVelocities=[0.0]))
    model.mbs.AddObject(ObjectMass1D(nodeNumber=node, mass=mass_kg))  # ADDMASS
    marker = model.mbs.AddMarker(MarkerNodeCoordinate(nodeNumber=node, coordinate=0))
    model.mbs.AddObject(ObjectConnectorCoordinateSpringDamper(
        markerNumbers=[model.bodies[body].marker_coordinate, marker], stiffness=stiffness_n_per_m))


@rpdrill.extension
def clamp(model, mass_kg: float = 100.0, body: str = "collar"):
    _mass(model, mass_kg, body=body)


@rpdrill.extension
def refuses_heavy(model, mass_kg: float = 100.0):
    if mass_kg > 500.0:
        raise ValueError(f"a clamp of {mass_kg} kg does not fit")  # REFUSES
    _mass(model, mass_kg)


@rpdrill.extension
def nan_spring(model):
    _mass(model, 100.0, stiffness_n_per_m=float("nan"))


@rpdrill.extension
def negative_mass(model):
    _mass(model, -5.0)


@rpdrill.extension
def zero_mass(model):
    _mass(model, 0.0)


@rpdrill.extension
def exits(model):
    sys.exit(0)  # EXITS


@rpdrill.extension
def typo(model):
    model.bodies["colar"]  # TYPO


@rpdrill.extension
def no_model(*, mass_kg: float = 1.0):
    pass


class Unspeakable(Exception):
    def __str__(self):
        raise RuntimeError("no words")


@rpdrill.extension
def unspeakable(model):
    raise Unspeakable()  # UNSPEAKABLE


def not_marked(model):
    open(CALLS, "a").write("called\\n")


def make_law(**parameters):
    return JenkinsRock(**parameters)


class Plain:
    def __init__(self, **parameters):
        open(CALLS, "a").write("constructed\\n")


class Empty(rpdrill.RockLaw):
    pass


@dataclass(frozen=True)
class RaisingLaw(JenkinsRock):
    def __post_init__(self):
        raise RuntimeError("my constructor")  # CONSTRUCTOR


@dataclass(frozen=True)
class ExitingLaw(JenkinsRock):
    def __post_init__(self):
        sys.exit(0)


@dataclass(frozen=True)
class BadForce(JenkinsRock):
    name: ClassVar[str] = "bad_force"

    def force(self, *args, **kwargs):
        raise NotImplementedError("my force")  # FORCE
'''


def line_of(source: str, mark: str) -> int:
    """The line of ``source`` that carries ``mark`` (a comment of the rig's)."""
    return next(i for i, line in enumerate(source.splitlines(), 1) if mark in line)


@pytest.fixture
def code(tmp_path, monkeypatch):
    """A folder on sys.path for the user's modules: ``code(name, source)`` writes one (the rig: ``code()``);
    the modules are forgotten before and after."""
    folder = tmp_path / "code"
    folder.mkdir()
    monkeypatch.syspath_prepend(str(folder))
    for name in MODULES:
        monkeypatch.delitem(sys.modules, name, raising=False)

    def write(name: str = "my_rig", source: str = RIG) -> Path:
        path = folder / f"{name}.py"
        path.write_text(textwrap.dedent(source), encoding="utf-8")
        return path

    yield write
    for name in [m for m in sys.modules if m.split(".")[0] in MODULES]:
        del sys.modules[name]


def scene_file(path: Path, **changes) -> Path:
    """The test drill (tests/test_drill.yaml), short, with ``changes`` (dotted key paths; ``extensions``)."""
    data = scene_dict(**SHORT, **changes)
    path.write_text(yaml.safe_dump(data, sort_keys=False), encoding="utf-8")
    return path


def extension(function: str, **parameters) -> dict:
    return {"extensions": {"rig": {"function": function, "parameters": parameters}}}


def run(capsys, *argv: str) -> tuple[int, str]:
    """A command in this process: its exit status and standard error."""
    try:
        status = main([str(a) for a in argv])
    except SystemExit as stop:  # argparse refuses its own arguments this way
        status = stop.code
    return status, capsys.readouterr().err


def clean(message: str) -> bool:
    return "Traceback" not in message and "internal error" not in message


# --- 1. A scene file runs no code without the user asking ---------------------------------------------------

def test_a_scene_naming_a_module_not_allowed_is_refused_before_anything_is_imported(code, tmp_path, capsys):
    """Why: a scene made rpdrill import any module on the path while it was read (``this:s`` printed the Zen
    of Python before the refusal)."""
    mark = tmp_path / "imported.txt"
    code("canary", f"open({str(mark)!r}, 'w').write('imported')\n\ndef run(model):\n    pass\n")
    scene = scene_file(tmp_path / "scene.yaml", **extension("canary:run"))
    status, message = run(capsys, "simulate", scene, "--out", tmp_path / "out", "--quiet")
    assert status == 2 and clean(message) and not mark.exists() and not (tmp_path / "out").exists()
    assert f"{scene}: extensions.rig.function: 'canary:run': module 'canary' is code of one's own" in message
    for way in ("--allow-code canary", "allow_code=['canary']", "entry point group 'rpdrill.extensions'"):
        assert way in message
    assert "this" not in sys.modules
    with pytest.raises(rpdrill.InputError, match="rock.law: 'this:s': module 'this' is code of one's own"):
        rpdrill.load_scene(scene_file(tmp_path / "zen.yaml", rock={"law": "this:s"}))
    assert "this" not in sys.modules and capsys.readouterr().out == ""


@pytest.mark.parametrize(("function", "parameters", "kind"), [
    ("os:spawnvp", {"mode": 0, "file": "sh", "args": ["sh", "-c", "touch {mark}"]}, "function"),
    ("os:system", {"command": "touch {mark}"}, "builtin_function_or_method"),
    ("subprocess:call", {"args": ["sh", "-c", "touch {mark}"]}, "function"),
    ("builtins:exec", {"source": "open({mark!r}, 'w')"}, "builtin_function_or_method"),
])
def test_a_scene_runs_no_shell_command_allowed_or_not(tmp_path, capsys, function, parameters, kind):
    """Why: ``os:spawnvp`` with {file: sh, args: [sh, -c, CMD]} ran CMD three times for one simulate, nine
    for a four-point study; os:system, subprocess:call and builtins:exec were imported and called."""
    mark = tmp_path / "ran.txt"
    given = {key: value.format(mark=str(mark)) if isinstance(value, str) else
             [v.format(mark=str(mark)) for v in value] if isinstance(value, list) else value
             for key, value in parameters.items()}
    scene = scene_file(tmp_path / "scene.yaml", **extension(function, **given))
    module = function.partition(":")[0]
    status, message = run(capsys, "simulate", scene, "--out", tmp_path / "out", "--quiet")
    assert status == 2 and clean(message) and f"module {module!r} is code of one's own" in message
    status, message = run(capsys, "simulate", scene, "--out", tmp_path / "out", "--quiet", "--allow-code", module)
    assert status == 2 and clean(message) and not mark.exists()
    assert f"extensions.rig.function: {function!r}: {kind}, not marked as an rpdrill extension" in message


def test_a_rock_law_popen_constructs_nothing_allowed_or_not(tmp_path, capsys):
    """Why: ``rock.law: subprocess:Popen`` with parameters {args: [sh, -c, CMD]} ran CMD while the scene was
    read, before the law was checked to be a rock law."""
    mark = tmp_path / "ran.txt"
    scene = scene_file(tmp_path / "scene.yaml", rock={"law": "subprocess:Popen",
                                                      "parameters": {"args": ["sh", "-c", f"touch {mark}"]}})
    status, message = run(capsys, "simulate", scene, "--out", tmp_path / "out", "--quiet")
    assert status == 2 and "rock.law: 'subprocess:Popen': module 'subprocess' is code of one's own" in message
    status, message = run(capsys, "simulate", scene, "--out", tmp_path / "out", "--quiet", "--allow-code", "subprocess")
    assert status == 2 and clean(message) and not mark.exists()
    assert "rock.law: 'subprocess:Popen': a class that does not subclass rocklaw.base.RockLaw" in message


def test_every_command_that_reads_scenes_refuses_code_not_allowed_and_no_file_allows_it(code, tmp_path, capsys):
    """Every command that reads a scene (a study's, a calibration's, a sensitivity study's, advise's,
    crosscheck's) refuses the module before it is imported, saying how to allow it; a file cannot allow it."""
    mark = tmp_path / "imported.txt"
    code("canary", f"open({str(mark)!r}, 'w').write('imported')\n")
    scene = scene_file(tmp_path / "scene.yaml", **extension("canary:run"))
    common = {"base_scene": str(scene), "frequency_hz": {"from": 40, "to": 60, "step": 10}}
    files = {
        "study": {"name": "s", "base_scene": str(scene), "scan": {"impact.frequency_hz": [50.0, 60.0]}},
        "calibrate": {"name": "c", **common, "parameters": {"impact.amplitude_n": {"bounds": [1e5, 3e5], "reason": "r"}},
                      "targets": [{"label": "a", "optimum_hz": 50, "band_hz": [45, 55]}]},
        "sensitivity": {"name": "s", **common, "scans": [{"label": "a"}], "parameters": ["impact.amplitude_n"]},
    }
    for command, data in files.items():
        path = tmp_path / f"{command}.yaml"
        path.write_text(yaml.safe_dump(data), encoding="utf-8")
        status, message = run(capsys, command, path, "--out", tmp_path / command, "--quiet")
        assert status == 2 and clean(message) and "--allow-code canary" in message, (command, message)
    for command, extra in (("advise", ["--frequency-hz", 40, 60, "--feed-kn", 20, 30]), ("crosscheck", [])):
        status, message = run(capsys, command, scene, "--out", tmp_path / command, *extra)
        assert status == 2 and clean(message) and "--allow-code canary" in message, (command, message)
    assert not mark.exists()
    smuggled = {**files["study"], "allow_code": ["canary"]}  # a file cannot allow code
    (tmp_path / "smuggled.yaml").write_text(yaml.safe_dump(smuggled), encoding="utf-8")
    status, message = run(capsys, "study", tmp_path / "smuggled.yaml", "--out", tmp_path / "s2", "--quiet")
    assert status == 2 and "allow_code: ['canary']: unknown key" in message
    inside = scene_file(tmp_path / "inside.yaml", allow_code=["canary"], **extension("canary:run"))
    status, message = run(capsys, "simulate", inside, "--out", tmp_path / "s3", "--quiet")
    assert status == 2 and "allow_code: ['canary']: unknown key" in message and not mark.exists()


def test_the_allowance_travels_with_the_scene_and_never_comes_from_its_file(code, tmp_path):
    code()
    path = scene_file(tmp_path / "scene.yaml", **extension("my_rig:clamp"))
    scene = rpdrill.load_scene(path, allow_code=["my_rig"])
    assert scene.allowed_code == ("my_rig",)
    for copy in (scene.with_({"impact.frequency_hz": 60.0}), scene.with_solver("exudyn", step_s=1e-5),
                 scene.model_copy(), pickle.loads(pickle.dumps(scene))):
        assert copy.allowed_code == ("my_rig",) and copy.extensions["rig"].found.target.__name__ == "clamp"
    simulation = pickle.loads(pickle.dumps(prepare(scene)))  # a worker's copy resolves it by name
    assert run_simulation(simulation).exudyn_model.extensions == ("rig",)
    data = yaml.safe_load(path.read_text())
    with pytest.raises(ValueError, match="module 'my_rig' is code of one's own"):
        rpdrill.Scene.model_validate(data)
    assert rpdrill.Scene.model_validate(data, context={"allow_code": "my_rig"}).allowed_code == ("my_rig",)
    plain = rpdrill.load_scene(ROOT / "tests" / "test_drill.yaml")
    with pytest.raises(rpdrill.InputError, match="Scene.with_: extensions.rig.function: 'my_rig:clamp': module"):
        plain.with_(extension("my_rig:clamp"))
    assert plain.with_(extension("my_rig:clamp"), allow_code=["my_rig"]).allowed_code == ("my_rig",)
    with pytest.raises(rpdrill.InputError, match=r"rpdrill.load_scene: allow_code: 5: give module names"):
        rpdrill.load_scene(path, allow_code=5)
    with pytest.raises(rpdrill.InputError, match="module 'my_rig' is code of one's own"):
        rpdrill.load_scene(path, allow_code=None)  # None allows nothing
    with pytest.raises(rpdrill.InputError, match="rpdrill.simulate: allow_code: 'my_rig:clamp': not a module name"):
        rpdrill.simulate(path, allow_code=["my_rig:clamp"])


def test_a_study_calls_an_extension_once_a_point_while_planned_and_once_in_its_run(code, tmp_path):
    """Why: a four-point study called the extension five times while it was planned: the estimate before the
    points are expanded built the extended model of the base scene too (now the drill's own, a lower bound),
    beside each point's (which sizes the step of the model its extensions make); a fixed step needs none."""
    calls = code().parent / "calls.txt"
    data = {"name": "counted", "base_scene": str(ROOT / "studies" / "scenes" / "paper_base.yaml"),
            "base_overrides": {**SHORT, **extension("my_rig:counted")},
            "scan": {"extensions.rig.parameters.mass_kg": [1.0, 2.0, 3.0, 4.0]}, "metrics": ["penetration_rate_m_per_s"]}
    (tmp_path / "study.yaml").write_text(yaml.safe_dump(data), encoding="utf-8")
    study = rpdrill.load_study(tmp_path / "study.yaml", allow_code=["my_rig"])
    assert calls.read_text().count("\n") == 4  # one a point: its budget's step
    table = rpdrill.run_study(study, workers=1)
    assert (table["status"] == "ok").all() and calls.read_text().count("\n") == 8  # and one a point's run
    calls.unlink()
    data["base_overrides"]["solver.step_s"] = 5e-5  # the step is the scene's: no model is built to size it
    (tmp_path / "study.yaml").write_text(yaml.safe_dump(data), encoding="utf-8")
    rpdrill.load_study(tmp_path / "study.yaml", allow_code=["my_rig"])
    assert not calls.exists()


def entry_points(registered: dict[str, list[tuple[str, str]]]):
    """importlib.metadata.entry_points as an installation with ``registered`` (group -> (name, value))."""
    def select(group: str):
        return importlib.metadata.EntryPoints(importlib.metadata.EntryPoint(name, value, group)
                                              for name, value in registered.get(group, []))
    return select


def test_code_registered_by_an_entry_point_runs_by_its_name_without_an_allowance(code, tmp_path, monkeypatch):
    code()
    monkeypatch.setattr(importlib.metadata, "entry_points", entry_points({
        "rpdrill.extensions": [("clamp", "my_rig:clamp"), ("unmarked", "my_rig:not_marked"), ("twice", "my_rig:clamp"),
                               ("twice", "my_rig:typo"), ("gone", "gone_rig:clamp"), ("lost", "my_rig:lost")],
        "rpdrill.rock_laws": [("raising", "my_rig:RaisingLaw"), ("plain", "my_rig:Plain")]}))
    scene = rpdrill.load_scene(scene_file(tmp_path / "scene.yaml", **extension("clamp", mass_kg=200.0)))
    assert scene.allowed_code == () and scene.extensions["rig"].found.entry_point == "rpdrill.extensions:clamp"
    assert rpdrill.simulate(scene).provenance["extensions"]["rig"]["import_path"] == "my_rig:clamp"
    for function, message in (
            ("unmarked", "'unmarked': function, not marked as an rpdrill extension"),
            ("twice", ("'twice': registered more than once in entry point group 'rpdrill.extensions': my_rig:clamp "
                      r"\(an entry point\), my_rig:typo")),
            ("gone", "'gone': entry point 'gone_rig:clamp' \\(an entry point\\): cannot import module 'gone_rig'"),
            ("lost", "'lost': entry point 'my_rig:lost' \\(an entry point\\) does not load: AttributeError"),
            ("crank", ("'crank': no installed package registers an extension named 'crank' \\(entry point group "
                      "'rpdrill.extensions': clamp, gone, lost, twice, unmarked\\)"))):
        with pytest.raises(rpdrill.InputError, match=f"extensions.rig.function: {message}"):
            scene.with_(extension(function))
    with pytest.raises(rpdrill.InputError, match="rock.law: 'raising': the law's constructor failed: RuntimeError"):
        scene.with_({"rock": {"law": "raising", "parameters": JENKINS}})
    with pytest.raises(rpdrill.InputError, match="rock.law: 'plain': a class that does not subclass"):
        scene.with_({"rock": {"law": "plain", "parameters": {}}})
    assert not (tmp_path / "code" / "calls.txt").exists()  # nothing of Plain constructed


def test_a_package_installed_with_entry_points_is_named_by_them_on_the_command_line(tmp_path, monkeypatch, capsys):
    """An installed distribution (a .dist-info with entry_points.txt on sys.path, as pip writes it)."""
    site = tmp_path / "site"
    info = site / "rigdist-1.0.dist-info"
    info.mkdir(parents=True)
    (info / "METADATA").write_text("Metadata-Version: 2.1\nName: rigdist\nVersion: 1.0\n", encoding="utf-8")
    (info / "entry_points.txt").write_text("[rpdrill.extensions]\nheavy_clamp = rigdist_mod:clamp\n\n"
                                           "[rpdrill.rock_laws]\nmy_jenkins = rigdist_mod:MyJenkins\n", encoding="utf-8")
    (site / "rigdist_mod.py").write_text(textwrap.dedent('''
        from exudyn.itemInterface import MarkerNodeCoordinate, Node1D, ObjectConnectorCoordinateSpringDamper, ObjectMass1D
        import rpdrill
        from rpdrill.rocklaw import JenkinsRock

        class MyJenkins(JenkinsRock):
            pass

        @rpdrill.extension
        def clamp(model, mass_kg: float):
            node = model.mbs.AddNode(Node1D(referenceCoordinates=[0.0], initialCoordinates=[0.0], initialVelocities=[0.0]))
            model.mbs.AddObject(ObjectMass1D(nodeNumber=node, mass=mass_kg, name="heavy_clamp"))
            marker = model.mbs.AddMarker(MarkerNodeCoordinate(nodeNumber=node, coordinate=0))
            model.mbs.AddObject(ObjectConnectorCoordinateSpringDamper(
                markerNumbers=[model.bodies["collar"].marker_coordinate, marker], stiffness=1e8))
        '''), encoding="utf-8")
    monkeypatch.syspath_prepend(str(site))
    monkeypatch.delitem(sys.modules, "rigdist_mod", raising=False)
    scene = scene_file(tmp_path / "scene.yaml", rock={"law": "my_jenkins", "parameters": JENKINS},
                       **extension("heavy_clamp", mass_kg=300.0))
    status, message = run(capsys, "simulate", scene, "--out", tmp_path / "out", "--quiet")
    assert status == 0, message
    provenance = json.loads((tmp_path / "out" / "summary.json").read_text())["provenance"]
    assert provenance["extensions"]["rig"] | {"parameters": None} == {
        "import_path": "rigdist_mod:clamp", "package": "rigdist", "version": "1.0", "parameters": None,
        "file": str(site / "rigdist_mod.py"), "entry_point": "rpdrill.extensions:heavy_clamp"}
    assert provenance["rock_law"]["entry_point"] == "rpdrill.rock_laws:my_jenkins"
    resolved = yaml.safe_load((tmp_path / "out" / "scene.resolved.yaml").read_text())
    assert resolved["extensions"]["rig"]["function"] == "heavy_clamp" and resolved["rock"]["law"] == "my_jenkins"
    sys.modules.pop("rigdist_mod", None)


# --- 2. The user's own code's errors are the user's ---------------------------------------------------------

BROKEN = {"syntax": "def clamp(model):\n    return (\n", "raises": "import math\n\nVALUE = 1 / 0\n",
          "exits": "import sys\n\nsys.exit(3)\n"}


@pytest.mark.parametrize(("source", "key", "words"), [
    ("syntax", "extensions.rig.function: 'broken:clamp'", ["failed to import: SyntaxError", "broken.py, line 2"]),
    ("raises", "extensions.rig.function: 'broken:clamp'", ["ZeroDivisionError: division by zero", "broken.py, line 3"]),
    ("exits", "extensions.rig.function: 'broken:clamp'", ["called sys.exit(3)", "broken.py, line 3"]),
    ("syntax", "rock.law: 'broken:Law'", ["failed to import: SyntaxError", "broken.py, line 2"]),
])
def test_a_module_that_does_not_import_is_bad_input_naming_the_key_and_the_users_line(code, tmp_path, capsys, source,
                                                                                        key, words):
    """Why: a module with a syntax error or raising on import gave a bare SyntaxError or an internal error."""
    code("broken", BROKEN[source])
    changes = {"rock": {"law": "broken:Law", "parameters": {}}} if key.startswith("rock") else extension("broken:clamp")
    scene = scene_file(tmp_path / "scene.yaml", **changes)
    status, message = run(capsys, "simulate", scene, "--out", tmp_path / "out", "--quiet", "--allow-code", "broken")
    assert status == 2 and clean(message) and f"{scene}: {key}: module 'broken' failed to import" in message
    assert all(word in message for word in words), message
    with pytest.raises(rpdrill.InputError, match="module 'broken' failed to import"):
        rpdrill.load_scene(scene, allow_code=["broken"])


@pytest.mark.parametrize(("function", "words", "mark"), [
    ("refuses_heavy", [("extensions.rig (my_rig:refuses_heavy) failed on the built model: ValueError: a clamp of 900.0 "
                       "kg does not fit")], "REFUSES"),
    ("nan_spring", ["the model with extensions.rig (my_rig:nan_spring) cannot be prepared", "not a finite number"], None),
    ("negative_mass", ["extensions.rig (my_rig:negative_mass) failed on the built model: ExudynValueError", "negative"],
     "ADDMASS"),
    ("zero_mass", ["Exudyn's solver stopped: SolverError", "singular", "extensions.rig (my_rig:zero_mass)"], None),
    ("exits", ["extensions.rig (my_rig:exits) failed on the built model: called sys.exit(0)"], "EXITS"),
    ("typo", [("extensions.rig (my_rig:typo) failed on the built model: KeyError: the built model has no body 'colar'; "
              "its body names: carriage, shank, collar, bit")], "TYPO"),
])
def test_an_extension_that_fails_is_a_failed_run_naming_it_and_the_users_line(code, tmp_path, capsys, function, words,
                                                                              mark):
    """Why: an extension that raised, added a NaN spring or a mass Exudyn refuses ended in 'rpdrill internal
    error ... please report it' or an undocumented ExtensionFailed; one that called sys.exit(0) ended the
    command with status 0 and no output; a typo'd body name was a bare KeyError 'colar'."""
    rig = code()
    scene = scene_file(tmp_path / "scene.yaml", **extension(f"my_rig:{function}",
                                                            **({"mass_kg": 900.0} if function == "refuses_heavy" else {})))
    status, message = run(capsys, "simulate", scene, "--out", tmp_path / "out", "--quiet", "--allow-code", "my_rig")
    # (one message, after Exudyn's own words as warnings where it printed any: a singular mass matrix)
    assert status == 1 and clean(message) and message.splitlines()[-1].startswith(f"{scene}: scene 'test_drill': ")
    assert all(word in message for word in words), message
    if mark:
        assert f"{rig}, line {line_of(RIG, mark)}" in message
    with pytest.raises(rpdrill.SimulationFailed, match=f"my_rig:{function}"):
        rpdrill.simulate(scene, allow_code=["my_rig"])


@pytest.mark.parametrize(("law", "status", "words"), [
    ("RaisingLaw", 2, ["rock.law: 'my_rig:RaisingLaw': the law's constructor failed: RuntimeError: my constructor",
                       "CONSTRUCTOR"]),
    ("ExitingLaw", 2, ["rock.law: 'my_rig:ExitingLaw': the law's constructor failed: called sys.exit(0)"]),
    ("BadForce", 1, ["scene 'test_drill': rock.law (my_rig:BadForce) raised NotImplementedError: my force", "FORCE"]),
])
def test_a_rock_law_of_ones_own_that_fails_names_rock_law_and_the_users_line(code, tmp_path, capsys, law, status, words):
    """Why: a rock law whose constructor raised (anything but a TypeError or ValueError) was an internal error."""
    rig = code()
    scene = scene_file(tmp_path / "scene.yaml", rock={"law": f"my_rig:{law}", "parameters": JENKINS})
    got, message = run(capsys, "simulate", scene, "--out", tmp_path / "out", "--quiet", "--allow-code", "my_rig")
    assert got == status and clean(message), message
    for word in words:
        assert (f"{rig}, line {line_of(RIG, word)}" if word.isupper() else word) in message, message


def test_a_studys_points_an_extension_refuses_fail_and_the_others_run(code, tmp_path, capsys):
    """Why: a study whose base_overrides add an extension that raises for some scan values ended in an
    internal error (the extension was called while the study was planned)."""
    rig = code()
    data = {"name": "heavy", "base_scene": str(ROOT / "tests" / "test_drill.yaml"),
            "base_overrides": {**SHORT, **extension("my_rig:refuses_heavy")},
            "scan": {"extensions.rig.parameters.mass_kg": [100.0, 900.0, 300.0]}, "metrics": ["penetration_rate_m_per_s"]}
    (tmp_path / "study.yaml").write_text(yaml.safe_dump(data), encoding="utf-8")
    status, message = run(capsys, "study", tmp_path / "study.yaml", "--out", tmp_path / "out", "--quiet", "--workers", 1,
                          "--allow-code", "my_rig")
    assert status == 1 and clean(message) and "2 points ok" in message and "1 failed" in message
    with (tmp_path / "out" / "results.csv").open(newline="") as handle:
        rows = {float(row["extensions.rig.parameters.mass_kg"]): row for row in csv.DictReader(handle)}
    assert rows[100.0]["status"] == rows[300.0]["status"] == "ok" and rows[900.0]["status"] == "failed"
    assert "extensions.rig (my_rig:refuses_heavy) failed on the built model: ValueError: a clamp of 900.0 kg does not " \
           f"fit ({rig}, line {line_of(RIG, 'REFUSES')})" in rows[900.0]["error"]
    data["base_overrides"] = {**SHORT, "solver.step_s": None, "solver.type": None, **extension("my_rig:typo")}
    data["scan"] = {"impact.frequency_hz": [50.0, 60.0]}  # every point fails, planned with the standard step
    (tmp_path / "all.yaml").write_text(yaml.safe_dump(data), encoding="utf-8")
    table = rpdrill.run_study(rpdrill.load_study(tmp_path / "all.yaml", allow_code=["my_rig"]), workers=1)
    assert (table["status"] == "failed").all()
    assert table["error"].str.contains("extensions.rig (my_rig:typo) failed on the built model: KeyError: the built "
                                       "model has no body 'colar'", regex=False).all()


# --- Misuse of the same kinds, with other numbers and files ---------------------------------------------------

@pytest.mark.parametrize(("changes", "allow", "status", "words"), [
    # a module allowed re-exports a dangerous callable: the attribute is not marked
    (extension("my_rig:os.system", command="true"), ["my_rig"], 2, [("'my_rig:os.system': builtin_function_or_method, "
                                                                    "not marked")]),
    (extension("my_rig:not_marked"), ["my_rig"], 2, ["'my_rig:not_marked': function, not marked"]),
    (extension("my_rigx:clamp"), ["my_rig"], 2, ["module 'my_rigx' is code of one's own"]),  # a prefix is no package
    (extension("rig_pkg.sub:clamp"), ["rig_pkg"], 0, []),  # a package allows its submodules
    (extension("rig_pkg:clamp"), ["rig_pkg.sub"], 2, ["module 'rig_pkg' is code of one's own"]),  # not its parents
    (extension("my_rig:"), ["my_rig"], 2, ["not an import path 'package.module:function'"]),
    (extension("clamp"), [], 2, [("no installed package registers an extension named 'clamp' (entry point group "
                                 "'rpdrill.extensions': none installed)")]),
    (extension("my_rig:clamp", mass_kg=100.0, body="colar"), ["my_rig"], 1, [("KeyError: the built model has no body "
                                                                              "'colar'")]),
    (extension("my_rig:clamp", mass="heavy"), ["my_rig"], 2, [("extensions.rig.parameters.mass: 'heavy': not a "
                                                              "parameter of my_rig:clamp")]),
    ({"rock": {"law": "my_rig:make_law", "parameters": JENKINS}}, ["my_rig"], 2, [("'my_rig:make_law': a function, "
                                                                                   "not a class")]),
    ({"rock": {"law": "my_rig:Plain", "parameters": {}}}, ["my_rig"], 2, [("'my_rig:Plain': a class that does not "
                                                                          "subclass rocklaw.base.RockLaw")]),
    ({"rock": {"law": "rate dependent"}}, [], 2, ["'rate dependent' is not a built-in law"]),
    ({"rock": {"law": "my_law", "parameters": {}}}, [], 2, ["no installed package registers a rock law named 'my_law'"]),
    ({"rock": {"law": "my_rig:RaisingLaw", "parameters": JENKINS}}, [], 2, ["module 'my_rig' is code of one's own"]),
    ({"rock": {"law": "my_rig:Empty", "parameters": {}}}, ["my_rig"], 2, [
        "not a rock law: it lacks name, state_names, bottom_index, crushes"]),
    (extension("my_rig:no_model"), ["my_rig"], 2, [("'my_rig:no_model': takes no model: an extension is called as "
                                                   "f(model, **parameters)")]),
    (extension("missing_rig:clamp"), ["missing_rig"], 2, [("cannot import module 'missing_rig' (No module named "
                                                          "'missing_rig')")]),
    (extension("needs_dep:clamp"), ["needs_dep"], 2, [("module 'needs_dep' failed to import: ModuleNotFoundError: No "
                                                      "module named 'not_installed_dep'"), "needs_dep.py, line 1"]),
    (extension("my_rig:unspeakable"), ["my_rig"], 1, [("extensions.rig (my_rig:unspeakable) failed on the built model: "
                                                      "Unspeakable ("), "my_rig.py, line"]),
    (extension("this"), [], 2, ["no installed package registers an extension named 'this'"]),  # nothing imported
    (extension("__import__('os').system"), [], 2, ["not a registered extension's name nor an import path"]),
])
def test_misuse_of_code_of_ones_own_is_refused_or_fails_cleanly(code, tmp_path, capsys, changes, allow, status, words):
    code()
    package = tmp_path / "code" / "rig_pkg"
    package.mkdir()
    (package / "__init__.py").write_text("", encoding="utf-8")
    (package / "sub.py").write_text("from my_rig import clamp\n", encoding="utf-8")
    code("needs_dep", "import not_installed_dep\n")
    scene = scene_file(tmp_path / "scene.yaml", **changes)
    options = [option for module in allow for option in ("--allow-code", module)]
    got, message = run(capsys, "simulate", scene, "--out", tmp_path / "out", "--quiet", *options)
    assert got == status and clean(message), message
    assert all(word in message for word in words), message
    assert not (tmp_path / "code" / "calls.txt").exists()  # nothing unmarked called, nothing unchecked constructed
    assert "this" not in sys.modules


@pytest.mark.parametrize(("argv", "words"), [
    (["--allow-code", "my_rig:clamp"], ("argument --allow-code: 'my_rig:clamp': not a module name such as 'my_rig' or "
                                       "'my_rig.clamps'; allow the module 'my_rig'")),
    (["--allow-code", "my rig"], "argument --allow-code: 'my rig': not a module name"),
    (["--allow-code", ""], "argument --allow-code: '': not a module name"),
])
def test_an_allowance_that_is_not_a_module_is_refused_by_the_command_line(tmp_path, capsys, argv, words):
    scene = scene_file(tmp_path / "scene.yaml")
    status, message = run(capsys, "simulate", scene, "--out", tmp_path / "out", "--quiet", *argv)
    assert status == 2 and words in message and not (tmp_path / "out").exists()


def test_registered_names_are_looked_up_per_sys_path_once(monkeypatch):
    """The entry points are read once per sys.path (a scene's validation reads them at every Scene.with_), and
    read again when sys.path changes."""
    reads = []
    monkeypatch.setattr(importlib.metadata, "entry_points", lambda group: reads.append(group) or ())
    for _ in range(3):
        assert registered("rpdrill.extensions") == ()
    monkeypatch.syspath_prepend("/nonexistent")
    registered("rpdrill.extensions")
    assert reads == ["rpdrill.extensions", "rpdrill.extensions"]


def test_any_command_says_whose_code_raised(code, tmp_path, capsys):
    """A law of one's own that raises inside a command's runs (crosscheck's windows, through the one run path) is
    a run that failed naming the key, the law and the user's line, not an internal error."""
    rig = code()
    scene = scene_file(tmp_path / "scene.yaml", rock={"law": "my_rig:BadForce", "parameters": JENKINS})
    status, message = run(capsys, "crosscheck", scene, "--blows", 4, "--allow-code", "my_rig")
    assert status == 1 and clean(message), message
    assert f"{scene}: scene 'test_drill': rock.law (my_rig:BadForce) raised NotImplementedError: my force ({rig}, " \
           f"line {line_of(RIG, 'FORCE')})" in message

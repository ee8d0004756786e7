"""A hole's scene at one depth: the rig with ``n`` rods of the string, the layer's rock and the operating point, as a
typed scene (models.definition.scene.Scene) and the data written as its YAML file.

The rig's rod chain is the path of connectors from its impact body to its rock body; its rods between the two
(wave rods: the rig's own extension rods) are the ones the string replaces.

* A top hammer (``hammer: top_hammer``): the rig's rods give way to ``rod1`` .. ``rodN`` of the string, joined by
  the string's ``coupling`` (default: the rig's connector between its first two rods, or a rigid joint), the
  rig's connector into its first rod now into ``rod1``, its connector out of its last rod out of ``rodN``. Every
  blow travels down the whole string.
* A down-the-hole hammer (``hammer: down_the_hole``): the hammer strikes the bit directly. The rig's rods are
  taken out and the impact body joined to the rock body by the rig's connector into the rock body (the piston's
  wave rod strikes the bit's shank); the ``n`` tubes above carry the feed and the rotation only: their mass is
  added to the body the feed acts on (the hammer's housing with the tubes, pushed by the feed). Their waves,
  their couplings and their friction in the hole are left out.

The scene asks for its steady state (``solver.steady_state: periodic``: for wave rods the blows run until the
per-blow figures settle, models.steady.wave_settling) and for the metrics the hole reads.
"""

from __future__ import annotations

import copy
from typing import Any

from ...models.definition.scene import Scene
from ...models.definition.validation import InputError, parse, set_path
from .hole_spec import Hole, rig_rods, rod_chain

HOLE_METRICS = ["penetration_rate_m_per_s", "advance_per_blow_m", "rock_energy_per_blow_j",
                "rock_transfer_efficiency", "energy_transfer_efficiency", "window_start_s", "window_blows"]


def scene_data(hole: Hole, rods: int, layer: int, operating: dict[str, Any] | None = None) -> dict[str, Any]:
    """The scene of ``hole`` with ``rods`` rods (tubes) in layer ``layer`` (module doc), ``operating`` scene key
    paths to values (an advised point), as data a scene file holds."""
    spec, rig = hole.spec, hole.rig
    data = rig.model_dump(by_alias=True, exclude_none=True, mode="json")
    string = data["drill_string"]
    chain, old = rod_chain(rig), rig_rods(rig)
    bodies, connectors = string["bodies"], string["connectors"]
    into = next(n for n, c in connectors.items() if c["to"] == old[0] and c["from"] == chain[chain.index(old[0]) - 1])
    out_of = next(n for n, c in connectors.items() if c["from"] == old[-1] and c["to"] == chain[chain.index(old[-1]) + 1])
    between = next((dict(c) for c in connectors.values() if c["from"] == old[0] and len(old) > 1 and c["to"] == old[1]),
                   {})
    kept_bodies = {name: body for name, body in bodies.items() if name not in old}
    kept = {name: c for name, c in connectors.items()
            if name not in (into, out_of) and c["from"] not in old and c["to"] not in old}
    if spec.hammer == "down_the_hole":
        new_bodies = {}
        new_connectors = {out_of: {**connectors[out_of], "from": connectors[into]["from"]}}
        fed = data["feed"].get("acts_on") or string["impact_body"]
        mass = kept_bodies[fed].get("mass_kg")
        if mass is None:
            raise InputError(f"{hole.source}: hammer: down_the_hole: the rig's feed acts on {fed!r}, which has no "
                             "mass_kg to carry the tubes' mass; give a rig whose feed acts on a body with a mass")
        kept_bodies[fed] = {**kept_bodies[fed], "mass_kg": mass + rods * spec.string.rod.mass_kg}
    else:
        names = [f"rod{i + 1}" for i in range(rods)]
        coupling = spec.string.coupling.model_dump(exclude_none=True) if spec.string.coupling else \
            {k: v for k, v in between.items() if k not in ("from", "to")}
        new_bodies = {name: spec.string.rod.body() for name in names}
        new_connectors = {into: {**connectors[into], "to": names[0]}}
        new_connectors.update({f"coupling{i + 1}": {"from": names[i], "to": names[i + 1], **coupling}
                               for i in range(rods - 1)})
        new_connectors[out_of] = {**connectors[out_of], "from": names[-1]}
    order = list(bodies)  # the rig's order, the new rods where its rods were
    first = order.index(old[0])
    string["bodies"] = {**{n: kept_bodies[n] for n in order[:first] if n in kept_bodies}, **new_bodies,
                        **{n: kept_bodies[n] for n in order[first:] if n in kept_bodies}}
    string["connectors"] = {**kept, **new_connectors}
    data["name"] = f"{spec.name}_{rods}rods_layer{layer + 1}"
    data["description"] = (f"{spec.name}: {rods} {'tubes' if spec.hammer == 'down_the_hole' else 'rods'}, layer "
                           f"{layer + 1} (to {spec.layers[layer].to_m:g} m), from the hole file {hole.source.name}")
    data["rock"] = dict(spec.layers[layer].rock)
    data["solver"]["steady_state"] = "periodic"
    data["outputs"] = {"metrics": list(HOLE_METRICS)}
    return apply_changes(data, operating or {})


def apply_changes(data: dict[str, Any], changes: dict[str, Any]) -> dict[str, Any]:
    """A copy of scene ``data`` with each dotted key path set to its value (None: the key taken out)."""
    data = copy.deepcopy(data)
    for path, value in changes.items():
        if value is not None:
            set_path(data, path, value)
            continue
        *parents, leaf = path.split(".")
        part = data
        for key in parents:
            part = part.get(key, {})
        part.pop(leaf, None)
    return data


def hole_scene(hole: Hole, rods: int, layer: int, operating: dict[str, Any] | None = None) -> Scene:
    """The typed scene of :func:`scene_data`; InputError naming the hole file and the layer's rock where the scene
    does not validate."""
    data = scene_data(hole, rods, layer, operating)
    return parse(Scene, data, f"{hole.source}: the scene at {rods} rods in layers.{layer}")

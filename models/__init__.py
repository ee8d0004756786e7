"""Drill models: the typed scene (definition), the drill's physics (drill), its formulations (solvers:
Exudyn, exact, ODE), rods as waves (waves), periodic steady states (steady) and results (evaluation)."""

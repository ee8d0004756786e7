"""Drill models: the typed scene, the Exudyn multibody model and its results."""

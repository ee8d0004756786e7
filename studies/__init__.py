"""YAML scenes and studies, and the ``rpdrill`` command line."""

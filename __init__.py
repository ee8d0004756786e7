"""rpdrill: multibody simulation of rotary-percussive rock drilling on Exudyn.

The public API (``docs/api.md``). The package's folders: ``rocklaw`` (the rock contact laws),
``models`` (the drill models and their formulations), ``studies`` (YAML inputs, scans, analyses,
reports and the command line); dependencies run one way, studies -> models -> rocklaw
(``docs/architecture.md``).
"""

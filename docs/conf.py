"""The documentation site of rpdrill (Sphinx), built strictly from the checkout:

    pip install -e ".[docs]"
    sphinx-build -W --keep-going -b html docs docs/_build/html

Pages: the Markdown files of docs/ (MyST), the gallery of examples/ (sphinx-gallery, every example run at
the build), the API reference from the docstrings of ``rpdrill.__all__`` and ``rpdrill.rocklaw.__all__``
(autodoc, autosummary and numpydoc; its pages are written at the build into docs/reference/generated/), the
Python blocks of the pages of ``page_examples`` run as printed (docs/page_examples.py).
Warnings are errors: a broken link, a page no toctree reaches, a docstring numpydoc cannot read, a page's Python
block that fails.
"""

from __future__ import annotations

import os
import sys
from importlib.metadata import version as _version
from pathlib import Path

DOCS = Path(__file__).resolve().parent
sys.path.insert(0, str(DOCS))  # gallery_arguments, page_examples

project = "rpdrill"
author = "the rpdrill authors"
copyright = "the rpdrill authors"
release = version = _version("rpdrill")

extensions = [
    "myst_parser",
    "sphinx.ext.autodoc",
    "sphinx.ext.autosummary",
    "sphinx.ext.mathjax",
    "sphinxcontrib.mermaid",
    "numpydoc",
    "sphinx_gallery.gen_gallery",
    "page_examples",
]

# the pages whose Python blocks run at the build, one process per page from the root of the checkout, and the
# text that marks a block not run alone (extending.md's worked connector type: tests/test_extending.py runs it);
# getting_started.md's blocks are run, and their output compared, by tests/test_docs_site.py
page_examples = {"api": (), "extending": ("class JointWithPlay",)}

source_suffix = {".rst": "restructuredtext", ".md": "markdown"}
root_doc = "index"
exclude_patterns = ["_build", "gallery/*.ipynb", "gallery/*.py", "gallery/*.md5", "gallery/*.zip",
                    "gallery/*.json"]

# MyST: GitHub's heading anchors (the pages link `model.md#rods-as-waves`), $...$ maths, ::: fences
myst_heading_anchors = 4
myst_enable_extensions = ["colon_fence", "dollarmath"]
myst_fence_as_directive = ["mermaid"]  # docs/architecture.md draws its routes as GitHub does

# the API reference: a page per public name, written at the build (docs/reference/generated/)
autosummary_generate = True
autosummary_imported_members = True
autodoc_default_options = {"members": True, "member-order": "bysource", "show-inheritance": True}
autodoc_preserve_defaults = True  # `reproduce(reproduction=DEFAULT)`, not the path of one checkout
autodoc_typehints = "none"  # numpydoc's Parameters sections carry the types
autodoc_class_signature = "separated"
numpydoc_show_class_members = False  # the class template lists the members
numpydoc_class_members_toctree = False
numpydoc_xref_param_type = False
templates_path = ["_templates"]


sphinx_gallery_conf = {
    "examples_dirs": [os.path.relpath(DOCS.parent / "examples", DOCS)],
    "gallery_dirs": ["gallery"],
    "filename_pattern": r"\.py$",  # every example is run
    "ignore_pattern": r"__init__\.py",
    "reset_argv": "gallery_arguments.example_arguments",  # each example's command line
    "download_all_examples": False,
    "remove_config_comments": True,
    "abort_on_example_error": True,
    "matplotlib_animations": False,
    "within_subsection_order": "FileNameSortKey",
    "write_computation_times": False,  # no timing page outside the toctrees
}

html_theme = "pydata_sphinx_theme"
html_title = "rpdrill"
html_theme_options = {
    "navigation_depth": 2,
    "show_toc_level": 2,
    "secondary_sidebar_items": ["page-toc"],
    "footer_start": ["copyright"],
    "footer_end": ["sphinx-version"],
}
html_show_sourcelink = False


def _signature_of_callables(app, what, name, obj, options, signature, return_annotation):
    """numpydoc's signature of an object that has one: a type alias (``rpdrill.rocklaw.State``, a callable
    ``tuple[float, ...]``) has none, and Sphinx 9 fails on the one numpydoc gives it."""
    from numpydoc.numpydoc import mangle_signature

    if signature is None and what in ("data", "attribute", "type"):
        return None
    return mangle_signature(app, what, name, obj, options, signature, return_annotation)


def _docs_of_reexported_data(app, what, name, obj, options, lines):
    """The ``#:`` comment of a name a package re-exports (``rpdrill.rocklaw.TABLE_1``, ``State``), from the
    module of the package that assigns it: autodoc reads comments only in the module it documents, and else
    gives the docstring of the value's type (``tuple`` for ``State``)."""
    if what != "data":
        return
    from sphinx.pycode import ModuleAnalyzer

    package, _, attribute = name.rpartition(".")
    for module_name, module in sorted(sys.modules.items()):
        if module_name.startswith(f"{package}.") and getattr(module, attribute, None) is obj:
            comment = ModuleAnalyzer.for_module(module_name).find_attr_docs().get(("", attribute))
            if comment:
                lines[:] = list(comment)
                return


def setup(app):
    app.connect("autodoc-process-docstring", _docs_of_reexported_data)
    from numpydoc.numpydoc import mangle_signature

    for listener in list(app.events.listeners["autodoc-process-signature"]):
        if listener.handler is mangle_signature:
            app.disconnect(listener.id)
    app.connect("autodoc-process-signature", _signature_of_callables)

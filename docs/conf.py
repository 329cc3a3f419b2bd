"""Sphinx configuration of robodyn's documentation: ``sphinx-build -W -b html docs docs/_build/html``
(the README's docs command). The user guide includes the README's sections (one source), the API
reference is generated from the docstrings, and the gallery scripts (``examples/gallery``) run
at build time."""

from __future__ import annotations

import os

import robodyn

os.environ.setdefault("MPLBACKEND", "Agg")

project = "robodyn"
author = "the robodyn authors"
release = version = getattr(robodyn, "__version__", "")
extensions = [
    "sphinx.ext.autodoc",
    "sphinx.ext.autosummary",
    "sphinx.ext.napoleon",
    "sphinx.ext.mathjax",
    "sphinx.ext.viewcode",
    "myst_parser",
    "sphinx_gallery.gen_gallery",
]
source_suffix = {".rst": "restructuredtext", ".md": "markdown"}
exclude_patterns = ["_build", "gallery/*.ipynb", "gallery/*.py", "gallery/*.zip", "gallery/*.json"]
html_theme = "furo"
html_title = "robodyn"
autosummary_generate = True
templates_path = ["_templates"]
autodoc_default_options = {"members": False}
autodoc_typehints = "none"
napoleon_google_docstring = True
napoleon_numpy_docstring = False
myst_heading_anchors = 3
myst_enable_extensions = ["dollarmath"]
# the README's own links (to files of the repository, not pages of the site) and the heading
# levels of its sections included below a page title
suppress_warnings = ["myst.header", "myst.xref_missing"]
sphinx_gallery_conf = {
    "examples_dirs": "../examples/gallery",
    "gallery_dirs": "gallery",
    "filename_pattern": r"/plot_",
    "download_all_examples": False,
    "remove_config_comments": True,
    "abort_on_example_error": True,
    "within_subsection_order": "FileNameSortKey",
    "show_memory": False,
    "plot_gallery": "True",
    "run_stale_examples": True,  # every build runs every script: the gallery is a test
}

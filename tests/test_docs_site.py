"""The README is a front page and the documentation site holds the rest: every page of docs/ is reachable from
its landing page, the README's links lead to pages that exist, its commands are the ones CI runs, and the
Getting started page's Python runs as printed, and the build runs the other pages' Python blocks. (The site
itself is built strictly by .ci/run: sphinx-build -W fails on a broken link, a page no toctree reaches, a
page's Python block that does not run.)"""

import re
import runpy
import subprocess
import sys
from pathlib import Path

from rpdrill.studies.pages.paper_pages import site_prefix

# the generated pages' links to the site's root
UNITS = ("rpdrill.studies.pages.paper_pages",)

ROOT = Path(__file__).resolve().parents[1]
DOCS = ROOT / "docs"
README = (ROOT / "README.md").read_text(encoding="utf-8")
GENERATED = ("_build", "gallery", "reference/generated")  # written by the build (.gitignore)


def test_the_readme_is_a_front_page():
    lines = README.splitlines()
    assert len(lines) < 150
    rows = [line for line in lines if line.startswith("|")]
    assert rows and max(map(len, rows)) <= 300


def test_the_readmes_links_lead_to_files_that_exist():
    targets = [target for target in re.findall(r"\]\(([^)#]+)", README) if "://" not in target]
    assert len(targets) > 10
    assert not [target for target in targets if not (ROOT / target).exists()]


def test_ci_runs_the_readmes_test_command_verbatim_and_builds_the_site_strictly():
    commands = re.findall(r"^    (pip install .*)$", README, re.MULTILINE)
    test = next(command for command in commands if "pytest" in command)
    ci = (ROOT / ".ci" / "run").read_text(encoding="utf-8").splitlines()
    assert test in ci
    assert any("sphinx-build -W --keep-going" in line and line.rstrip().endswith("docs docs/_build/html") for line in ci)


def toctree_entries(page: Path) -> list[Path]:
    """The pages a Markdown page's toctrees list, as files of docs/ (an entry may omit its suffix)."""
    entries = []
    for block in re.findall(r"```\{toctree\}\n(.*?)```", page.read_text(encoding="utf-8"), re.DOTALL):
        for line in block.splitlines():
            if line.strip() and not line.startswith(":"):
                entry = page.parent / line.strip()
                entries.append(next((entry.with_name(entry.name + suffix) for suffix in (".md", ".rst")
                                     if entry.with_name(entry.name + suffix).exists()), entry))
    return entries


def test_every_page_is_reachable_from_the_landing_page():
    pages = {path for path in DOCS.rglob("*.md") if not str(path.relative_to(DOCS)).startswith(GENERATED)}
    reached, todo = set(), [DOCS / "index.md"]
    while todo:
        page = todo.pop()
        if page in reached or page.suffix != ".md":
            continue
        reached.add(page)
        todo += toctree_entries(page)
    assert not sorted(str(page.relative_to(DOCS)) for page in pages - reached)


def test_generated_pages_link_the_sites_pages_from_the_folder_they_are_copied_into(tmp_path):
    (tmp_path / "conf.py").write_text("project = 'site'\n", encoding="utf-8")
    (tmp_path / "fig6" / "best_drill").mkdir(parents=True)
    assert site_prefix(tmp_path) == ""
    assert site_prefix(tmp_path / "fig6" / "best_drill") == "../../"
    assert site_prefix(None) == ""
    assert (DOCS / "fig6" / "best_drill" / site_prefix(DOCS / "fig6" / "best_drill")).resolve() == DOCS.resolve()
    links = re.findall(r"\]\(([^)]+\.md)\)", (DOCS / "fig6" / "best_drill" / "reproduction.md").read_text(encoding="utf-8"))
    assert "../../model.md" in links and not [link for link in links if not (DOCS / "fig6" / "best_drill" / link).exists()]


def test_the_getting_started_python_runs_as_printed(tmp_path):
    blocks = re.findall(r"```python\n(.*?)```", (DOCS / "getting_started.md").read_text(encoding="utf-8"), re.DOTALL)
    assert len(blocks) == 2  # a change of a scene; an extension's module
    printed = []
    for code in blocks:
        done = subprocess.run([sys.executable, "-c", code], cwd=tmp_path, capture_output=True, text=True,
                              check=False, timeout=300)
        assert done.returncode == 0, done.stderr
        printed.append(done.stdout)
    assert printed[0] == "15.6 mm/s\n"  # the rate the page shows for the changed scene


def test_the_sites_build_runs_every_page_with_python_blocks():
    """Every page with Python blocks is run by the build (docs/conf.py's ``page_examples``) but Getting started,
    whose output the test above compares."""
    configured = runpy.run_path(str(DOCS / "conf.py"))["page_examples"]
    with_blocks = {path.stem for path in DOCS.glob("*.md") if "```python\n" in path.read_text(encoding="utf-8")}
    assert set(configured) | {"getting_started"} == with_blocks


def test_a_python_block_that_does_not_run_alone_is_a_problem_at_its_line(tmp_path):
    """docs/page_examples.py (what the build reports as warnings, errors of the strict build): each block runs in a
    namespace of its own from the folder above the pages' (the second uses a name of the first: a NameError, at its
    line); a block marked not to run alone is not run; a block that prints a traceback is a problem too."""
    page_examples = runpy.run_path(str(DOCS / "page_examples.py"))
    source = tmp_path / "docs"
    source.mkdir()
    (tmp_path / "here.txt").write_text("the root", encoding="utf-8")
    (source / "page.md").write_text(
        "# Page\n\n```python\nx = open('here.txt').read()\n```\n\nText.\n\n```python\nprint(x)\n```\n\n"
        "```python\nraise SystemExit('NOT ALONE')\n```\n\n```python\nimport sys\nprint('Traceback', file=sys.stderr)\n```\n",
        encoding="utf-8")
    problems = page_examples["page_problems"](source, {"page": ("NOT ALONE",)})
    assert [(page, line) for page, line, _ in problems] == [("page", 10), ("page", 18)]
    assert "NameError: name 'x' is not defined" in problems[0][2] and "NOT ALONE" not in str(problems)

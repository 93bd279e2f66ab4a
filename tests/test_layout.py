"""The package's layout: no import cycles, a command line on the public API only,
and numpydoc docstrings on every public name.

* the module-level imports of linmstmm's modules (found with ``ast``, imports
  inside functions excluded) form a graph without a cycle;
* the modules of ``linmstmm/cli/`` import from linmstmm only the package itself,
  each other, and modules that docs/api.md names, and no private name;
* every public name in ``linmstmm.__all__`` and every public method of its
  classes (and every public function of a public module there) has a
  docstring with a numpydoc ``Parameters`` section when it takes parameters
  and a ``Returns`` section when it returns a value, as python-control's
  docstring test asks;
* no module of linmstmm is over LONG_MODULE (500) lines unless its docstring
  has a paragraph starting "Kept whole:" that says why it is not split.
"""
from __future__ import annotations

import ast
import inspect
import re
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest

import linmstmm

PACKAGE = Path(linmstmm.__file__).resolve().parent
API_GUIDE = PACKAGE.parent / "docs" / "api.md"


def module_name(path: Path) -> str:
    """``linmstmm.cli.freqs`` for ``linmstmm/cli/freqs.py``, ``linmstmm.cli`` for its ``__init__.py``."""
    parts = path.relative_to(PACKAGE.parent).with_suffix("").parts
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


MODULES = {module_name(path): path for path in sorted(PACKAGE.rglob("*.py"))}


def module_level_imports(path: Path) -> list[tuple[str, list[str]]]:
    """(module, imported names) of every import run when ``path`` is imported.

    Imports inside functions and classes are left out (they run on first use
    only); ``if``/``try`` blocks at module level count.
    """
    name = module_name(path)
    package = name if path.name == "__init__.py" else name.rpartition(".")[0]
    found = []

    def visit(statements):
        for node in statements:
            if isinstance(node, ast.Import):
                found.extend((alias.name, []) for alias in node.names)
            elif isinstance(node, ast.ImportFrom):
                base = node.module or ""
                if node.level:
                    base = ".".join(package.split(".")[:len(package.split(".")) - node.level + 1] + [base]).strip(".")
                found.append((base, [alias.name for alias in node.names]))
            elif isinstance(node, (ast.If, ast.Try)):
                visit(node.body + node.orelse + getattr(node, "finalbody", [])
                      + [n for handler in getattr(node, "handlers", []) for n in handler.body])
    visit(ast.parse(path.read_text()).body)
    return found


def import_graph() -> dict[str, set[str]]:
    """linmstmm module -> the linmstmm modules it imports at module level.

    ``from linmstmm.pkg import name`` depends on ``linmstmm.pkg.name`` where that
    is a module, else on ``linmstmm.pkg``.
    """
    graph = {}
    for name, path in MODULES.items():
        targets = set()
        for module, names in module_level_imports(path):
            if module != "linmstmm" and not module.startswith("linmstmm."):
                continue
            submodules = {f"{module}.{n}" for n in names} & MODULES.keys()
            targets |= submodules or {module}
        graph[name] = targets - {name}
    return graph


def find_cycle(graph: dict[str, set[str]]) -> list[str]:
    """One cycle of ``graph`` as a list of nodes (first repeated at the end), or []."""
    state, stack = {}, []

    def visit(node):
        state[node] = "open"
        stack.append(node)
        for target in sorted(graph.get(node, ())):
            if state.get(target) == "open":
                return stack[stack.index(target):] + [target]
            if target not in state and (cycle := visit(target)):
                return cycle
        state[node] = "done"
        stack.pop()
        return []

    for node in sorted(graph):
        if node not in state and (cycle := visit(node)):
            return cycle
    return []


def test_the_cycle_finder_finds_a_cycle():
    assert find_cycle({"a": {"b"}, "b": {"c"}, "c": {"a"}, "d": set()}) == ["a", "b", "c", "a"]
    assert find_cycle({"a": {"b"}, "b": {"c"}, "c": set(), "d": {"a", "c"}}) == []


def test_the_graph_sees_the_command_line():
    graph = import_graph()
    assert "linmstmm.cli.common" in graph["linmstmm.cli"]
    assert "linmstmm.cli.common" in graph["linmstmm.cli.freqs"]


def test_module_level_imports_have_no_cycle():
    cycle = find_cycle(import_graph())
    assert not cycle, " -> ".join(cycle)


def documented_modules() -> set[str]:
    """The linmstmm modules docs/api.md names (``linmstmm.x`` or ``linmstmm.x.name``)."""
    named = set(re.findall(r"\blinmstmm(?:\.\w+)+", API_GUIDE.read_text()))
    return {prefix for name in named for prefix in _prefixes(name)} & MODULES.keys()


def _prefixes(name: str):
    parts = name.split(".")
    return (".".join(parts[:i]) for i in range(1, len(parts) + 1))


CLI_MODULES = sorted(name for name in MODULES if name == "linmstmm.cli" or name.startswith("linmstmm.cli."))


@pytest.mark.parametrize("name", CLI_MODULES)
def test_the_command_line_uses_the_public_api_only(name):
    allowed = documented_modules() | {"linmstmm"} | set(CLI_MODULES)
    tree = ast.parse(MODULES[name].read_text())
    for node in ast.walk(tree):  # function-level imports too
        if isinstance(node, ast.ImportFrom) and (node.module or "").startswith("linmstmm"):
            assert node.module in allowed, f"{name} imports {node.module}, which docs/api.md does not document"
            private = [alias.name for alias in node.names
                       if alias.name.startswith("_") and not alias.name.endswith("__")]
            assert not private, f"{name} imports private {private} from {node.module}"
            if node.module == "linmstmm":
                outside = {alias.name for alias in node.names} - set(linmstmm.__all__) - {"__version__"}
                assert not outside, f"{name} imports {outside}, not in linmstmm.__all__"


# --- docstrings --------------------------------------------------------------------

def _sections(doc: str) -> set[str]:
    """The numpydoc section titles of ``doc`` (a title line underlined by dashes)."""
    lines = inspect.cleandoc(doc).splitlines()
    return {lines[i].strip() for i in range(len(lines) - 1)
            if lines[i].strip() and set(lines[i + 1].strip()) == {"-"}
            and len(lines[i + 1].strip()) >= len(lines[i].strip())}


def _takes_parameters(function) -> bool:
    parameters = [p for p in inspect.signature(function).parameters.values() if p.name not in ("self", "cls")]
    return bool(parameters)


def _returns_value(function) -> bool:
    """Whether ``function`` returns something: by its annotation, else by a ``return x`` in its source."""
    annotation = inspect.signature(function).return_annotation
    if annotation is not inspect.Signature.empty:
        return annotation not in (None, "None")
    tree = ast.parse(textwrap.dedent(inspect.getsource(function)))
    return any(isinstance(node, ast.Return) and node.value is not None for node in ast.walk(tree.body[0]))


def documented_callables():
    """(qualified name, function) of every public function and method the API exposes."""
    found = []
    for name in linmstmm.__all__:
        value = getattr(linmstmm, name)
        if inspect.ismodule(value):
            found += [(f"{name}.{n}", f) for n, f in vars(value).items()
                      if inspect.isfunction(f) and not n.startswith("_") and f.__module__ == value.__name__]
        elif inspect.isclass(value):
            for n, member in vars(value).items():
                if inspect.isfunction(member) and not n.startswith("_"):
                    found.append((f"{name}.{n}", member))
        elif inspect.isfunction(value) or callable(value):
            found.append((name, inspect.unwrap(value)))
    return found


@pytest.mark.parametrize("name, function", [pytest.param(*pair, id=pair[0]) for pair in documented_callables()])
def test_public_functions_have_numpydoc_sections(name, function):
    doc = inspect.getdoc(function)
    assert doc, f"{name} has no docstring"
    sections = _sections(doc)
    if _takes_parameters(function):
        assert "Parameters" in sections, f"{name}: no Parameters section"
    if _returns_value(function):
        assert "Returns" in sections, f"{name}: no Returns section"


@pytest.mark.parametrize("name", [n for n in linmstmm.__all__ if inspect.isclass(getattr(linmstmm, n))])
def test_public_classes_have_docstrings(name):
    assert inspect.getdoc(getattr(linmstmm, name)), f"{name} has no docstring"


def test_the_section_reader_reads_numpydoc():
    doc = """Summary.

    Parameters
    ----------
    x : float

    Returns
    -------
    float
    """
    assert _sections(doc) == {"Parameters", "Returns"}
    assert _sections("Summary.\n\nx : float, the value") == set()


# --- module length -----------------------------------------------------------------

#: Modules longer than this many lines must say why they are not split.
LONG_MODULE = 500
#: The start of the module docstring's paragraph that says so.
KEPT_WHOLE = "Kept whole:"


def kept_whole_reason(source: str) -> str:
    """The paragraph of ``source``'s module docstring that starts with KEPT_WHOLE and
    gives a reason after it, or ""."""
    doc = ast.get_docstring(ast.parse(source)) or ""
    for paragraph in doc.split("\n\n"):
        paragraph = paragraph.strip()
        if paragraph.startswith(KEPT_WHOLE) and paragraph[len(KEPT_WHOLE):].strip():
            return paragraph
    return ""


def unexplained_long_modules(paths) -> list[str]:
    """Those of ``paths`` over LONG_MODULE lines without a kept-whole reason."""
    return [str(path) for path in paths
            if len(path.read_text().splitlines()) > LONG_MODULE and not kept_whole_reason(path.read_text())]


def test_no_long_module_without_a_reason_to_stay_whole():
    long = unexplained_long_modules(MODULES.values())
    assert not long, f"over {LONG_MODULE} lines, no '{KEPT_WHOLE}' paragraph at the top: {long}"


def test_the_length_check_sees_a_long_module(tmp_path):
    body = "x = 1\n" * LONG_MODULE
    files = {"short.py": '"""Short."""\n' + "x = 1\n" * (LONG_MODULE - 1),
             "long.py": '"""Long."""\n' + body,
             "empty_reason.py": '"""Long.\n\nKept whole:\n"""\n' + body,
             "kept.py": '"""Long.\n\nKept whole: one idea, one loop.\n"""\n' + body}
    for name, text in files.items():
        (tmp_path / name).write_text(text)
    found = unexplained_long_modules(sorted(tmp_path / name for name in files))
    assert found == [str(tmp_path / "empty_reason.py"), str(tmp_path / "long.py")]


def test_starting_the_command_line_leaves_the_heavy_modules_unimported():
    """scipy.optimize (0.1 s), matplotlib, numba and python-flint are imported where a
    command needs them, not by every command's start-up (``import linmstmm.cli``)."""
    heavy = ("scipy.optimize", "matplotlib", "numba", "flint")
    script = f"import sys, linmstmm.cli; print([m for m in {heavy!r} if m in sys.modules])"
    output = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, check=True).stdout
    assert output.strip() == "[]"


def test_a_solve_by_the_command_line_imports_what_it_runs():
    """``linmstmm freqs`` on the launcher (the numpy engine, no mpmath refinement) imports
    its own command only: neither mpmath nor the other commands' modules (mode shapes,
    response, damped roots, the FE route's eigensolver), which a new process would
    otherwise compile or load for nothing (a sixth of its start-up)."""
    unused = ("mpmath", "numba", "linmstmm.modes", "linmstmm.response", "linmstmm.damped",
              "linmstmm.fe.eigensolver", "linmstmm.cli.modes", "scipy.sparse.linalg")
    script = ("import contextlib, io, sys; from linmstmm.cli import main\n"
              "with contextlib.redirect_stdout(io.StringIO()):\n"
              "    status = main(['freqs', 'models/mlrs/mlrs.toml'])\n"
              f"print(status, [m for m in {unused!r} if m in sys.modules])")
    output = subprocess.run([sys.executable, "-c", script], cwd=PACKAGE.parent, capture_output=True, text=True,
                            check=True).stdout
    assert output.strip() == "0 []"

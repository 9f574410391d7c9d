"""Issue 41: the Python package has no import cycles. A module's imports
that run when it is imported (module level, in module-level if/try blocks
and class bodies; not inside functions, not under TYPE_CHECKING) form a
graph of addon/tempera's modules, which must have no cycle: a cycle makes
the import order matter and half-initialized modules possible."""
import ast
import sys

from conftest import ROOT

ADDON = ROOT / "addon"


def _modules(root):
    """{dotted name: (path, is_package)} of every .py module under root/tempera."""
    out = {}
    for path in (root / "tempera").rglob("*.py"):
        parts = list(path.relative_to(root).with_suffix("").parts)
        is_package = parts[-1] == "__init__"
        out[".".join(parts[:-1] if is_package else parts)] = (path, is_package)
    return out


def _imports_at_import_time(body):
    for node in body:
        if isinstance(node, (ast.Import, ast.ImportFrom)):
            yield node
        elif isinstance(node, ast.If) and "TYPE_CHECKING" not in ast.unparse(node.test):
            yield from _imports_at_import_time(node.body + node.orelse)
        elif isinstance(node, ast.Try):
            handlers = [n for h in node.handlers for n in h.body]
            yield from _imports_at_import_time(node.body + handlers + node.orelse + node.finalbody)
        elif isinstance(node, ast.ClassDef):
            yield from _imports_at_import_time(node.body)


def _targets(node, package, modules):
    """The package modules an import statement runs or reads: `from P import n`
    is P.n when that is a module (the native extension too), else P's __init__."""
    if isinstance(node, ast.Import):
        return [a.name for a in node.names]
    base = node.module or ""
    if node.level:
        parts = package.split(".")
        base = ".".join(parts[:len(parts) - node.level + 1] + ([node.module] if node.module else []))
    named = [f"{base}.{a.name}" for a in node.names]
    return [n if n in modules or n.endswith("._native") else base for n in named]


def import_graph(root):
    modules = _modules(root)
    graph = {name: set() for name in modules}
    for name, (path, is_package) in modules.items():
        package = name if is_package else name.rpartition(".")[0]
        for node in _imports_at_import_time(ast.parse(path.read_text()).body):
            graph[name].update(t for t in _targets(node, package, modules) if t in modules and t != name)
    return graph


def cycles(graph):
    """The strongly connected components of more than one module (Tarjan)."""
    index, low, stack, on_stack, found = {}, {}, [], set(), []
    sys.setrecursionlimit(max(sys.getrecursionlimit(), 10 * len(graph) + 100))

    def visit(v):
        index[v] = low[v] = len(index)
        stack.append(v)
        on_stack.add(v)
        for w in graph[v]:
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on_stack:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            component = []
            while not component or component[-1] != v:
                component.append(stack.pop())
                on_stack.discard(component[-1])
            if len(component) > 1:
                found.append(sorted(component))

    for v in sorted(graph):
        if v not in index:
            visit(v)
    return found


def test_the_package_has_no_import_cycle():
    graph = import_graph(ADDON)
    assert len(graph) > 50 and "tempera.blender.stylize_operator" in graph
    assert graph["tempera.blender.methods.rigid"] >= {"tempera.blender.stylize_operator"}
    assert cycles(graph) == []


def test_a_cycle_is_found(tmp_path):
    """Two modules importing each other at module level (one through its
    package's __init__, as `from . import name` does) are a cycle; an import
    inside a function is not."""
    package = tmp_path / "tempera"
    (package / "sub").mkdir(parents=True)
    (package / "__init__.py").write_text("from .sub.a import A\n")
    (package / "sub" / "__init__.py").write_text("")
    (package / "sub" / "a.py").write_text("from .b import B\nA = 1\n")
    (package / "sub" / "b.py").write_text("def later():\n    from .a import A\nB = 2\n")
    assert cycles(import_graph(tmp_path)) == []
    (package / "sub" / "b.py").write_text("from .. import A\nB = 2\n")
    assert cycles(import_graph(tmp_path)) == [["tempera", "tempera.sub.a", "tempera.sub.b"]]

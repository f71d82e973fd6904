"""The type stub python/spar/__init__.pyi against the built module: the same public names,
classes with the same members, functions with the same parameters and defaults; the compiled
part's docstrings are the stub's (python/docstrings.py), and no public docstring is C++ text."""
import ast
import inspect
import pathlib
import re

import pytest

import spar

STUB_PATH = pathlib.Path(spar.__file__).with_name("__init__.pyi")
STUB = ast.parse(STUB_PATH.read_text(encoding="utf-8"))
CLASSES = {node.name: node for node in STUB.body if isinstance(node, ast.ClassDef)}
FUNCTIONS = {node.name: node for node in STUB.body if isinstance(node, ast.FunctionDef)}
CPP_TEXT = re.compile(r"\w::\w|\.hpp\b|\.cpp\b|#include|\bconst [A-Za-z_]+&")


def stub_parameters(function):
    """[(name, has_default)] of a stub function, self left out."""
    args = function.args
    positional = args.posonlyargs + args.args
    defaults = [False] * (len(positional) - len(args.defaults)) + [True] * len(args.defaults)
    out = [(a.arg, d) for a, d in zip(positional, defaults)]
    out += [(a.arg, d is not None) for a, d in zip(args.kwonlyargs, args.kw_defaults)]
    if args.kwarg:
        out.append(("**" + args.kwarg.arg, False))
    return [p for p in out if p[0] != "self"]


def split_top_level(text):
    parts, depth, current = [], 0, ""
    for char in text:
        depth += char in "([{"
        depth -= char in ")]}"
        if char == "," and depth == 0:
            parts.append(current.strip())
            current = ""
        else:
            current += char
    return parts + ([current.strip()] if current.strip() else [])


def runtime_parameters(function):
    """[(name, has_default)] of a Python function or of a pybind11 one (its signature line)."""
    try:
        signature = inspect.signature(function)
    except ValueError:
        line = function.__doc__.splitlines()[0]
        inside = line[line.index("(") + 1:line.rindex(") ->")]
        out = []
        for part in split_top_level(inside):
            name = part.split(":")[0].strip()
            out.append((name, "=" in part))
        return [p for p in out if p[0] != "self"]
    out = []
    for p in signature.parameters.values():
        if p.kind is p.VAR_KEYWORD:
            out.append(("**" + p.name, False))
        else:
            out.append((p.name, p.default is not p.empty))
    return [p for p in out if p[0] != "self"]


def is_compiled(obj):
    return getattr(obj, "__module__", "") == "spar._spar" or type(obj).__name__ in (
        "builtin_function_or_method", "instancemethod", "property")


def test_the_stub_names_what_the_package_exports():
    names = set(CLASSES) | set(FUNCTIONS) | {
        node.target.id for node in STUB.body if isinstance(node, ast.AnnAssign)}
    assert names == set(spar.__all__) | {"__version__"}


@pytest.mark.parametrize("name", sorted(FUNCTIONS))
def test_a_function_has_the_stub_parameters(name):
    assert runtime_parameters(getattr(spar, name)) == stub_parameters(FUNCTIONS[name]), name


@pytest.mark.parametrize("name", sorted(CLASSES))
def test_a_class_has_the_stub_members(name):
    runtime = getattr(spar, name)
    stub_members = {m.name: m for m in CLASSES[name].body if isinstance(m, ast.FunctionDef)}
    public = {m for m in vars(runtime) if not m.startswith("_")}
    if issubclass(runtime, Exception):
        public -= set(vars(Exception))
    assert public == {m for m in stub_members if not m.startswith("_")}, name
    for member, node in stub_members.items():
        value = getattr(runtime, member)
        if isinstance(value, property) or type(value).__name__ == "property":
            continue
        if member in ("__eq__", "__len__"):
            continue
        assert runtime_parameters(value) == stub_parameters(node), f"{name}.{member}"


def stub_docstrings():
    yield "", spar._spar, STUB
    for name, node in CLASSES.items():
        yield name, getattr(spar, name), node
        for member in node.body:
            if isinstance(member, ast.FunctionDef):
                yield f"{name}.{member.name}", getattr(getattr(spar, name), member.name), member
    for name, node in FUNCTIONS.items():
        yield name, getattr(spar, name), node


@pytest.mark.parametrize("name,obj,node", list(stub_docstrings()), ids=lambda x: str(x)[:40])
def test_compiled_docstrings_are_the_stubs(name, obj, node):
    text = ast.get_docstring(node)
    if not is_compiled(obj) and name:
        # A pure-Python function (spar/__init__.py) keeps its own docstring.
        assert obj.__doc__, name
        return
    if text:
        assert inspect.cleandoc(text) in inspect.cleandoc(obj.__doc__ or ""), name


def public_objects():
    for name in spar.__all__:
        obj = getattr(spar, name)
        yield name, obj
        if inspect.isclass(obj):
            for member, value in vars(obj).items():
                if not member.startswith("_") or member == "__init__":
                    yield f"{name}.{member}", value


@pytest.mark.parametrize("name,obj", list(public_objects()), ids=lambda x: str(x)[:40])
def test_no_docstring_is_cpp_text(name, obj):
    doc = inspect.getdoc(obj) or ""
    assert not CPP_TEXT.search(doc), f"{name}: {doc}"

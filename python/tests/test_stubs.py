"""The type stubs (mlcp/__init__.pyi) name every public function, class, method and property
with the module's own parameters and defaults."""

import ast
import inspect
import pathlib

import mlcp

STUB = pathlib.Path(mlcp.__file__).with_name("__init__.pyi")


def stub_tree():
    tree = ast.parse(STUB.read_text())
    return {node.name: node for node in tree.body
            if isinstance(node, (ast.FunctionDef, ast.ClassDef))}


def stub_params(fn):
    args = fn.args
    names = [a.arg for a in args.args]
    defaults = [ast.literal_eval(d) if not isinstance(d, ast.Name) else d.id
                for d in args.defaults]
    return names, defaults


def runtime_params(fn):
    sig = inspect.signature(fn)
    names = list(sig.parameters)
    defaults = [p.default for p in sig.parameters.values() if p.default is not inspect.Parameter.empty]
    return names, defaults


def test_every_public_name_is_stubbed():
    stubs = stub_tree()
    assert set(mlcp.__all__) <= set(stubs)


def test_function_signatures_match():
    stubs = stub_tree()
    for name in ("solve", "run", "solvers", "engines", "sweep", "stability"):
        assert stub_params(stubs[name]) == runtime_params(getattr(mlcp, name)), name


def test_class_members_match():
    stubs = stub_tree()
    for cls_name in ("Problem", "Result", "Run"):
        cls = getattr(mlcp, cls_name)
        members = {n.name: n for n in stubs[cls_name].body if isinstance(n, ast.FunctionDef)}
        fields = {n.target.id for n in stubs[cls_name].body if isinstance(n, ast.AnnAssign)}
        public = {n for n in dir(cls) if not n.startswith("_")}
        if hasattr(cls, "__dataclass_fields__"):
            public |= set(cls.__dataclass_fields__)
        assert public == (set(members) - {"__init__"}) | fields, cls_name
        for name, node in members.items():
            attr = inspect.getattr_static(cls, name)
            if isinstance(attr, property):
                continue
            fn = getattr(cls, name)
            names, defaults = runtime_params(fn)
            if isinstance(attr, classmethod):
                names = ["cls"] + names
            assert stub_params(node) == (names, defaults), f"{cls_name}.{name}"


def test_typed_solver_parameters_are_stubbed_with_their_types_and_defaults():
    """_NewtonParams, _DantzigParams, _LemkeParams and _ProximalParams list every typed parameter the module
    takes, with its type and, first in its comment, its default."""
    lines = STUB.read_text().splitlines()
    stubs = stub_tree()
    stubbed = {}
    for solver in ("newton", "dantzig", "lemke", "proximal"):
        for node in stubs[f"_{solver.capitalize()}Params"].body:
            if isinstance(node, ast.AnnAssign):
                default = lines[node.lineno - 1].split("#", 1)[1].split(",")[0].strip()
                stubbed[(solver, node.target.id)] = (node.annotation.id, ast.literal_eval(default))
    actual = {(solver, name): (kind, default)
              for solver, name, kind, default, _, _ in mlcp._mlcp.solver_params()}
    assert stubbed == actual

"""The type stub libvox/__init__.pyi is kept in step with the module: the same public names, the same parameters in
the same order and kinds with the same defaults, the same Grid members; and every public name has a docstring."""

import ast
import inspect
import pathlib

import pytest

import libvox
import libvox._libvox as native

STUB = pathlib.Path(libvox.__file__).with_name("__init__.pyi")


def stub_tree():
    return ast.parse(STUB.read_text())


def public(names):
    return {n for n in names if not n.startswith("_")}


def stub_functions(body):
    return {n.name: n for n in body if isinstance(n, ast.FunctionDef)}


def native_signature(obj, name):
    """The parameters pybind11 writes on the first line of a function's docstring, as an ast.arguments."""
    first = obj.__doc__.splitlines()[0]
    assert first.startswith(name + "("), first
    params = first[len(name) + 1:first.rindex(") -> ")]
    return ast.parse(f"def f({params}): pass").body[0].args


def compare_arguments(stub, real, where):
    def kinds(args):
        names = [a.arg for a in args.posonlyargs + args.args]
        return names, [a.arg for a in args.kwonlyargs]

    assert kinds(stub) == kinds(real), where
    stub_defaults = stub.defaults + [d for d in stub.kw_defaults if d is not None]
    real_defaults = real.defaults + [d for d in real.kw_defaults if d is not None]
    assert len(stub_defaults) == len(real_defaults), where
    assert [d is None for d in stub.kw_defaults] == [d is None for d in real.kw_defaults], where
    for s, r in zip(stub_defaults, real_defaults):
        if isinstance(s, ast.Constant) and s.value is Ellipsis:
            continue  # the stub leaves it unsaid (inf)
        assert ast.unparse(s) == ast.unparse(r), f"{where}: default {ast.unparse(s)} != {ast.unparse(r)}"


def test_same_public_names():
    tree = stub_tree()
    stub_names = {n.name for n in tree.body if isinstance(n, (ast.FunctionDef, ast.ClassDef))}
    assert public(stub_names) == public(dir(native)) - {"annotations"}
    assert set(libvox.__all__) == public(stub_names)
    assert isinstance(libvox.__version__, str)


@pytest.mark.parametrize("name", sorted(public(n for n in dir(native) if callable(getattr(native, n))
                                               and not isinstance(getattr(native, n), type))))
def test_function_signatures(name):
    stub = stub_functions(stub_tree().body)[name]
    compare_arguments(stub.args, native_signature(getattr(native, name), name), name)
    assert len(inspect.getdoc(getattr(native, name)).splitlines()) > 3  # a docstring beyond the signature


def test_grid_members():
    cls = next(n for n in stub_tree().body if isinstance(n, ast.ClassDef) and n.name == "Grid")
    stub_members = stub_functions(cls.body)
    stub_props = {n for n, f in stub_members.items()
                  if any(isinstance(d, ast.Name) and d.id == "property" for d in f.decorator_list)}
    real = {n: getattr(native.Grid, n) for n in public(dir(native.Grid))}
    real_props = {n for n, v in real.items() if isinstance(v, property)}
    assert stub_props == real_props
    assert set(stub_members) == set(real)
    for name in set(real) - real_props:
        compare_arguments(stub_members[name].args, native_signature(real[name], name), f"Grid.{name}")
        assert len(inspect.getdoc(real[name]).splitlines()) > 2, name
    for name in real_props:
        assert real[name].__doc__ and len(real[name].__doc__.splitlines()[-1]) > 10, name


def test_exceptions_in_stub():
    classes = {n.name: n for n in stub_tree().body if isinstance(n, ast.ClassDef)}
    for name, base in [("InputError", "ValueError"), ("UsageError", "ValueError"), ("LimitError", "MemoryError")]:
        assert [ast.unparse(b) for b in classes[name].bases] == [base]
        assert getattr(libvox, name).__bases__ == (getattr(__builtins__, base, None) or eval(base),)
        assert getattr(libvox, name).__doc__

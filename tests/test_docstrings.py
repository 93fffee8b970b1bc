"""A docstring on every public class and function of the package (methods included; an override may inherit
its base's), so that ``help()`` answers for everything a user or a plug-in author touches."""

from __future__ import annotations

import dataclasses
import importlib
import inspect
import pkgutil
import sys
import types

import spacepol


def undocumented(modules) -> list[str]:
    """Qualified names of the public classes, functions and methods defined in ``modules`` without a docstring."""
    missing = []
    for module in modules:
        for name, obj in vars(module).items():
            if name.startswith("_") or getattr(obj, "__module__", None) != module.__name__:
                continue
            if inspect.isfunction(obj) and not (obj.__doc__ or "").strip():
                missing.append(f"{module.__name__}.{name}")
            elif inspect.isclass(obj):
                own = (obj.__dict__.get("__doc__") or "").strip()
                if not own or own.startswith(f"{name}("):  # a dataclass's generated signature is not a docstring
                    missing.append(f"{module.__name__}.{name}")
                for attr, member in vars(obj).items():
                    if attr.startswith("_"):
                        continue
                    if isinstance(member, property):
                        documented = inspect.getdoc(member)
                    elif inspect.isfunction(getattr(member, "__func__", member)):
                        documented = inspect.getdoc(getattr(obj, attr))  # an override inherits its base's
                    else:
                        continue
                    if not documented:
                        missing.append(f"{module.__name__}.{name}.{attr}")
    return missing


def package_modules():
    return [importlib.import_module(info.name) for info in pkgutil.walk_packages(spacepol.__path__, "spacepol.")]


def test_every_public_class_and_function_has_a_docstring():
    modules = package_modules()
    assert len(modules) > 80
    assert undocumented(modules) == []


def test_the_check_finds_what_is_missing():
    """Negative control: an undocumented function, class, method, property and dataclass (its generated signature is
    no docstring) are all reported; documented ones and private names are not."""
    module = types.ModuleType("spacepol_fake")
    code = '''
def bare(): pass
def told():
    """Documented."""
def _private(): pass
class Bare:
    def method(self): pass
    @property
    def value(self): return 1
class Told:
    """Documented."""
    def method(self):
        """Documented."""
@dataclasses.dataclass
class Record:
    value: float
@dataclasses.dataclass
class Described:
    """Documented."""
    value: float
'''
    module.__dict__["dataclasses"] = dataclasses
    sys.modules[module.__name__] = module  # a dataclass looks its module up there
    try:
        exec(compile(code, "spacepol_fake", "exec"), module.__dict__)
    finally:
        del sys.modules[module.__name__]
    assert sorted(undocumented([module])) == ["spacepol_fake.Bare", "spacepol_fake.Bare.method", "spacepol_fake.Bare.value",
                                              "spacepol_fake.Record", "spacepol_fake.bare"]


def long_module_docstrings(paths, limit: int = 10) -> list[str]:
    """'path: N lines' for each module in ``paths`` whose docstring runs past ``limit`` lines."""
    import ast

    out = []
    for path in paths:
        doc = ast.get_docstring(ast.parse(path.read_text(encoding="utf-8")), clean=False)
        if doc and len(doc.strip().splitlines()) > limit:
            out.append(f"{path}: {len(doc.strip().splitlines())} lines")
    return out


def test_a_module_docstring_says_what_the_module_is_for_in_ten_lines(tmp_path):
    """The long form (why, what was measured) lives on the documentation's internals page. Control: an eleven-line
    docstring is found."""
    from pathlib import Path

    package = Path(spacepol.__file__).parent
    found = long_module_docstrings(sorted(package.rglob("*.py")))
    assert not found, "; ".join(found)
    long = tmp_path / "long.py"
    long.write_text('"""' + "\n".join(f"line {i}" for i in range(11)) + '"""\n', encoding="utf-8")
    assert long_module_docstrings([long]) == [f"{long}: 11 lines"]

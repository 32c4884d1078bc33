"""The type stubs name exactly what the native module has: a method added
to a class without its stub (or a stub left after a rename) fails here."""

import ast
import pathlib

import guiding

STUB = pathlib.Path(guiding.__file__).with_name("_guiding.pyi")


def stub_classes():
    tree = ast.parse(STUB.read_text())
    classes = {c.name: c for c in tree.body if isinstance(c, ast.ClassDef)}

    def members(c):
        names = {
            n.name
            for n in c.body
            if isinstance(n, ast.FunctionDef) and not n.name.startswith("__")
        }
        for base in c.bases:
            if isinstance(base, ast.Name) and base.id in classes:
                names |= members(classes[base.id])
        return names

    return {name: members(c) for name, c in classes.items() if not name.startswith("_")}


def test_stubs_match_the_module():
    stubs = stub_classes()
    for name in guiding.__all__:
        obj = getattr(guiding, name)
        if not isinstance(obj, type):
            continue
        real = {m for m in dir(obj) if not m.startswith("_")}
        assert stubs[name] == real, (name, stubs[name] ^ real)

"""The mutation check (tools/mutation_check.py, a developer command too slow for CI) must not rot:
every mutation's text occurs exactly once in its file, so each still mutates the code it names."""
import importlib.util
import os

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))


def test_every_mutation_applies_to_the_current_source():
    spec = importlib.util.spec_from_file_location("mutation_check", os.path.join(ROOT, "tools", "mutation_check.py"))
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    assert len(module.MUTATIONS) >= 15
    stale = []
    for m in module.MUTATIONS:
        with open(os.path.join(ROOT, m.path)) as f:
            count = f.read().count(m.old)
        if count != 1:
            stale.append(f"{m.name}: {m.path} holds its text {count} times")
    assert not stale, stale

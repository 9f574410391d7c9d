"""The docs' copies of the native tables are current."""
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "tools"))
import option_docs  # noqa: E402


def test_engine_option_table_in_the_docs_is_current():
    text = (ROOT / "docs" / "engine.md").read_text()
    assert option_docs.render(text) == text, "run tools/option_docs.py"


def test_every_method_in_the_docs_is_current():
    """docs/methods.md says what the registry holds (issue 41, step 4: the option docs iterate it)."""
    text = (ROOT / "docs" / "methods.md").read_text()
    assert option_docs.render_methods(text) == text, "run tools/option_docs.py"
    from tempera.methods import registry

    for m in registry.METHODS:
        assert f"## `--method {m['name']}`" in text

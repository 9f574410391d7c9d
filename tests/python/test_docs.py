"""The docs' copies of the native tables are current."""
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "tools"))
import option_docs  # noqa: E402


def test_engine_option_table_in_the_docs_is_current():
    text = (ROOT / "docs" / "engine.md").read_text()
    assert option_docs.render(text) == text, "run tools/option_docs.py"

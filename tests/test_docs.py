"""docs/models.md stays true: its engine-mapping table is the one the code computes."""

from demcheck.engines import mapping

from .conftest import ROOT


def test_mapping_table_in_docs_is_current():
    text = (ROOT / "docs" / "models.md").read_text()
    start = text.index("<!-- mapping-table:start -->\n") + len("<!-- mapping-table:start -->\n")
    end = text.index("<!-- mapping-table:end -->")
    assert text[start:end] == mapping.markdown_table()

"""docs/scenario-format.md is exactly what `crater schema --markdown` prints, so every key the
loader accepts is documented with its type, unit, default and range."""
import sys
import unittest

from crater_test import SOURCE_DIR, crater


class DocsInSync(unittest.TestCase):
    def test_scenario_format_md(self):
        generated = crater("schema", "--markdown").stdout
        on_disk = (SOURCE_DIR / "docs/scenario-format.md").read_text()
        self.assertEqual(on_disk, generated,
                         "docs/scenario-format.md is stale: run `make docs` and commit it")


if __name__ == "__main__":
    unittest.main(argv=sys.argv[:1], verbosity=2)

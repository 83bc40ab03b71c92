# ctest-timeout: 120
"""Defaults are stated once (issue 23): the schema (src/io/scenario/scenario_schema.cpp and the
material laws' entries, material_laws.cpp) is the only place a scenario key's default is
written. The structs the reader fills (src/io/scenario/config.hpp and the methods'
settings.hpp) state none: every data member is left without an initialiser or zero-initialised
with `{}`, so nothing is indeterminate and no second default can drift from the schema's.

The few members that keep a value are listed below with the reason; each belongs to a key for
which the schema states no default (`crater schema --markdown` shows "unset"), so the value is
not a second statement of one. A member added with a value, a listed member that is gone, and a
listed key that gains a schema default all fail. The scanner itself is shown to catch `= 1.3`,
`{1.3}` and `= Kind::A`, and to pass `{}`."""
import re
import sys
import unittest

from crater_test import SOURCE_DIR, crater

HEADERS = ["src/io/scenario/config.hpp", "src/sph/settings.hpp", "src/dem/settings.hpp",
           "src/fem/settings.hpp"]

# (header, struct, member) -> (schema table, key, why the member keeps its value)
KEEP = {
    ("src/dem/settings.hpp", "PackingSettings", "porosity"):
        ("[parts.packing]", "porosity",
         "required with method = \"random\", unset otherwise; 0.4 stands in the settled-packing "
         "cache key of lattice packings (dem::packing_key_text), which must not change"),
    ("src/fem/settings.hpp", "BoundarySettings", "components"):
        ("[[parts.fem.boundary]]", "components",
         "unset means every component is imposed (the schema's help says so); the reader sets "
         "them only when the key is given"),
    ("src/io/scenario/config.hpp", "ProbesConfig", "lining_axis_direction"):
        ("[probes]", "lining_axis_direction",
         "unset means along y (the schema's help says so): a schema default would put the key "
         "into every scenario's [probes], where the reader refuses it without probes.lining; "
         "the reader sets it only when the key is given"),
}


def members(text):
    """(struct, member, initialiser or None) for every data member of every struct in text."""
    text = re.sub(r"//[^\n]*", "", text)
    out = []
    for m in re.finditer(r"\bstruct\s+(\w+)\s*(?::[^{;]*)?\{", text):
        depth, i, start = 1, m.end(), m.end()
        statements, current = [], ""
        while depth and i < len(text):
            c = text[i]
            if c == "{":
                depth += 1
            elif c == "}":
                depth -= 1
            if depth >= 1:
                current += c
            # A statement ends at `;`, or at the `}` of a function body (not of `x{...};`).
            closes_body = c == "}" and not text[i + 1:].lstrip().startswith((";", ","))
            if depth == 1 and (c == ";" or closes_body):
                statements.append(current)
                current = ""
            i += 1
        for s in statements:
            s = " ".join(s.split())
            if not s.endswith(";") or "(" in s or s.startswith(("using ", "static ", "friend ", "struct ", "enum ", "class ")):
                continue
            d = re.match(r"^(?:[\w:<>,\s*&]+?)\s(\w+)\s*(=\s*(.+?)|(\{.*\}))\s*;$", s)
            if d:
                init = d.group(3) if d.group(3) is not None else d.group(4)
                out.append((m.group(1), d.group(1), init.strip()))
            elif re.match(r"^[\w:<>,\s*&]+\s\w+\s*;$", s):
                out.append((m.group(1), s.rstrip(";").split()[-1], None))
    return out


def stated_values(header, text):
    """Members that state a value: initialised with anything but `{}`."""
    return [(header, s, name, init) for s, name, init in members(text)
            if init is not None and init != "{}"]


def schema_default(markdown, table, key):
    """The default column of `key` in the markdown section of `table` ("unset", "**required**"
    or a literal)."""
    section = markdown.split(f"## `{table}`\n", 1)[1].split("\n## ", 1)[0]
    row = re.search(rf"^\| `{re.escape(key)}` \|(.*)$", section, re.M)
    return re.split(r"(?<!\\)\|", row.group(1))[2].strip()


class DefaultsOnce(unittest.TestCase):
    def test_the_scanner_sees_values(self):
        text = ("struct A {\n  Real h = 1.3;\n  Real k{1.3};\n  Kind kind = Kind::A;\n"
                "  Real z{};\n  std::vector<Face> walls;\n  bool any() const { return z; }\n};\n")
        found = {(name, init) for _, _, name, init in stated_values("x", text)}
        self.assertEqual(found, {("h", "1.3"), ("k", "{1.3}"), ("kind", "Kind::A")})
        names = {name for _, name, _ in members(text)}
        self.assertEqual(names, {"h", "k", "kind", "z", "walls"})

    def test_the_scanner_reads_the_headers(self):
        # Enough members seen in each header that a scanner gone blind would fail here.
        for header in HEADERS:
            found = members((SOURCE_DIR / header).read_text())
            self.assertGreater(len(found), 5, header)

    def test_no_settings_struct_states_a_default(self):
        stated = []
        for header in HEADERS:
            stated += stated_values(header, (SOURCE_DIR / header).read_text())
        unexpected = [f"{h}: {s}::{n} = {v}" for h, s, n, v in stated if (h, s, n) not in KEEP]
        self.assertEqual(unexpected, [],
                         "a settings struct states a value: the schema states defaults; leave "
                         "the member `{}` (or list it in KEEP with the reason)")
        gone = [k for k in KEEP if k not in {(h, s, n) for h, s, n, _ in stated}]
        self.assertEqual(gone, [], "KEEP lists a member that no longer states a value")

    def test_kept_values_have_no_schema_default(self):
        markdown = crater("schema", "--markdown").stdout
        for (header, struct, member), (table, key, why) in KEEP.items():
            with self.subTest(member=f"{struct}::{member}"):
                self.assertEqual(schema_default(markdown, table, key), "unset",
                                 f"{table} {key} now has a schema default: {struct}::{member} "
                                 f"must not state another ({why})")


if __name__ == "__main__":
    unittest.main(argv=sys.argv[:1], verbosity=2)

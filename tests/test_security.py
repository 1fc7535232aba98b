"""No string of a case reaches an engine as a command, and files are written as any other tool writes them.

The engines read a deck line by line (split at "\\n" only); a line whose first character is "#" is a
comment; a line whose last printable character is "&" continues onto the next one (even a comment line);
LAMMPS's triple quotes span lines. A case's free text (its name, variant labels, material names) is
validated when the case is read (one line, exit 2), and every free text the deck writers put into a comment
or a data-file title is made one printable line; a final guard refuses any deck line demcheck does not
write. The tests below write decks from hostile strings through every route and check that every line
outside the comments is one demcheck wrote, and run both engines on the strongest string that gets past
the case validation (a writer fed directly).
"""

import dataclasses
import os
import subprocess
import sys
from pathlib import Path

import pytest

from demcheck import case as C
from demcheck.errors import ConfigError, DemcheckError
from demcheck.engines import family_deck as FD, mapping, registry
from demcheck.inputs import common, packing_decks

from .conftest import CASES, ROOT

ENGINES = ("lammps", "liggghts")
WRITERS = {"lammps": registry.get("lammps").collision_deck, "liggghts": registry.get("liggghts").collision_deck}
PACKING_WRITERS = {"lammps": registry.get("lammps").packing_deck, "liggghts": registry.get("liggghts").packing_deck}

# {f}: a file the injected command would create
HOSTILE = {
    "newline": "x\nshell touch {f} #",
    "crlf": "x\r\nshell touch {f} #",
    "cr": "x\rshell touch {f} #",
    "two-lines": "x\nshell touch {f}\nprint done #",
    "trailing-ampersand": "x &",
    "ampersand-newline": "x &\nshell touch {f} #",
    "dollar": "x ${{f}} $(v_a) $a",
    "quotes": "x \"\"\" ' \" shell touch {f}",
    "backslash": "x \\",
    "hash": "x # y",
    "u2028": "x\u2028shell touch {f} #",
    "u2029": "x\u2029shell touch {f} #",
    "u0085": "x\x85shell touch {f} #",
    "vertical-tab": "x\x0bshell touch {f} #",
    "nul": "x\x00shell touch {f} #",
    "bidi": "x\u202eshell touch {f} #",
    "long-line": "x" * 100_000,
    "long": "x" * 100_000 + "\nshell touch {f} #",
}
BENIGN_NAMES = ["glass-pair", "suite-walton[angle=5,spin=1500]", "a b (c) d/e: f=1, g+h_2.5",
                "Gläser-3.18mm", "speed=1e-05,position=[1.0, 0.0, -2.5]"]


def hostile(kind: str, target: Path) -> str:
    return HOSTILE[kind].format(f=target)


# ----------------------------------------------------------------------------- what a safe deck is


def engine_lines(text: str) -> list[str]:
    """The deck as the engines split it into lines."""
    return text.split("\n")


def is_comment(line: str) -> bool:
    return line.lstrip(" ").startswith("#")


def assert_safe(text: str) -> None:
    """Every line is printable, none continues onto the next, no triple quotes."""
    for ch in text:
        assert ch == "\n" or ch.isprintable(), f"non-printable {ch!r} in the deck"
    assert '"""' not in text
    for line in engine_lines(text):
        assert not line.rstrip().endswith("&"), line[-80:]


def assert_same_commands(text: str, benign: str, secret: str | None = None) -> None:
    """Line for line, the deck is the benign deck except in comment lines: every line outside the comments
    is one demcheck wrote, and the hostile text appears only in comments."""
    assert_safe(text)
    got, want = engine_lines(text), engine_lines(benign)
    assert len(got) == len(want), "the hostile text added or removed lines"
    for a, b in zip(got, want):
        if a != b:
            assert is_comment(a) and is_comment(b), (a[:120], b[:120])
    if secret:
        for line in got:
            if secret in line:
                assert is_comment(line), line[:120]


def assert_same_data(files: dict, benign: dict) -> None:
    """A data file: the title line (a comment, skipped by read_data) may differ, nothing else."""
    assert files.keys() == benign.keys()
    for name in files:
        assert_safe(files[name])
        got, want = engine_lines(files[name]), engine_lines(benign[name])
        assert len(got) == len(want), name
        assert got[0].startswith("#") and got[1:] == want[1:], name


# ----------------------------------------------------------------------------- the case refuses them


def _case_text(name_line: str, extra: str = "") -> str:
    text = (CASES / "glass-pair.toml").read_text()
    text = text.replace('name = "glass-pair"', name_line)
    return text + extra


def _toml_string(s: str) -> str:
    """A TOML basic string holding s exactly."""
    out = []
    for ch in s:
        if ch in '"\\':
            out.append("\\" + ch)
        elif not ch.isprintable() or ord(ch) < 0x20:
            out.append(f"\\u{ord(ch):04x}" if ord(ch) <= 0xFFFF else f"\\U{ord(ch):08x}")
        else:
            out.append(ch)
    return '"' + "".join(out) + '"'


def _one_line_config_error(exc: ConfigError, key: str) -> None:
    text = str(exc)
    assert "\n" not in text and "\r" not in text and text.isprintable(), text[:200]
    assert exc.key == key, text[:200]
    assert len(text) < 400


@pytest.mark.parametrize("kind", sorted(HOSTILE))
def test_a_hostile_name_in_the_case_file_is_refused(kind, tmp_path):
    f = tmp_path / "PWNED"
    path = tmp_path / "case.toml"
    path.write_text(_case_text(f"name = {_toml_string(hostile(kind, f))}"))
    with pytest.raises(ConfigError) as info:
        C.load(path)
    _one_line_config_error(info.value, "name")
    with pytest.raises(ConfigError) as info:
        C.expand(path)
    _one_line_config_error(info.value, "name")


@pytest.mark.parametrize("kind", sorted(HOSTILE))
def test_a_hostile_name_through_set_is_refused(kind, tmp_path):
    f = tmp_path / "PWNED"
    with pytest.raises(ConfigError) as info:
        C.load(CASES / "glass-pair.toml", [f"name={_toml_string(hostile(kind, f))}"])
    _one_line_config_error(info.value, "name")


@pytest.mark.parametrize("kind", sorted(HOSTILE))
def test_a_hostile_variant_label_is_refused(kind, tmp_path):
    """A variant value is a user string too: it becomes part of the variant's name."""
    f = tmp_path / "PWNED"
    path = tmp_path / "case.toml"
    values = f'["hertz", {_toml_string(hostile(kind, f))}]'
    path.write_text(_case_text('name = "v"', f'\n[variants]\n"contact.normal" = {values}\n'))
    with pytest.raises(ConfigError) as info:
        C.expand(path)
    _one_line_config_error(info.value, "variants.contact.normal")


def test_a_hostile_variant_key_is_refused(tmp_path):
    path = tmp_path / "case.toml"
    path.write_text(_case_text('name = "v"', '\n[variants]\n"impact.speed\\nshell touch F #" = [1.0, 2.0]\n'))
    with pytest.raises(ConfigError) as info:
        C.expand(path)
    assert info.value.key.startswith("variants.") and "\n" not in str(info.value)


@pytest.mark.parametrize("name", BENIGN_NAMES)
def test_real_names_are_accepted(name):
    assert C.load(CASES / "glass-pair.toml", [f"name={_toml_string(name)}"]).name == name


def test_real_variant_labels_are_accepted(tmp_path):
    path = tmp_path / "case.toml"
    path.write_text(_case_text('name = "v"', '\n[variants]\n"impact.speed" = [1e-5, 2.0]\n'
                               '"run.method" = ["adaptive", "verlet"]\n'))
    names = [c.name for c in C.expand(path)]
    assert names == ["v[speed=1e-05,method=adaptive]", "v[speed=1e-05,method=verlet]", "v[speed=2,method=adaptive]",
                     "v[speed=2,method=verlet]"]


@pytest.mark.parametrize("value", ["5", "1.5", "true", "[\"a\"]", "{ a = 1 }", "\"\""])
def test_a_name_that_is_not_a_one_line_string_is_refused(value, tmp_path):
    path = tmp_path / "case.toml"
    path.write_text(_case_text(f"name = {value}"))
    with pytest.raises(ConfigError) as info:
        C.load(path)
    _one_line_config_error(info.value, "name")


def test_a_hostile_material_name_is_refused(tmp_path):
    path = tmp_path / "case.toml"
    bad = _toml_string("glass\nshell touch F #")
    path.write_text((CASES / "glass-pair.toml").read_text().replace("[materials.glass]", f"[materials.{bad}]")
                    .replace('material = "glass"', f"material = {bad}"))
    with pytest.raises(ConfigError) as info:
        C.load(path)
    assert info.value.key.startswith("materials.") and "\n" not in str(info.value)


def test_a_file_name_that_breaks_the_name_rule_is_named_as_the_cause(tmp_path):
    path = tmp_path / "it's $HOME.toml"
    path.write_text((CASES / "glass-pair.toml").read_text().replace('name = "glass-pair"\n', ""))
    with pytest.raises(ConfigError) as info:
        C.load(path)
    _one_line_config_error(info.value, "name")
    assert "file" in info.value.rule


# ----------------------------------------------------------------------------- the writers neutralise them


def _collision_case(wall: bool):
    return C.load(CASES / ("oblique-lsd-wall.toml" if wall else "glass-pair.toml"))


def _packing_case():
    return C.load(CASES / "packing" / "column-lsd.toml")


def _renamed(case, name):
    return dataclasses.replace(case, name=name)


@pytest.mark.parametrize("kind", sorted(HOSTILE))
@pytest.mark.parametrize("engine", ENGINES)
@pytest.mark.parametrize("wall", [False, True])
def test_collision_decks_keep_a_hostile_name_in_comments(kind, engine, wall, tmp_path):
    case = _collision_case(wall)
    text = hostile(kind, tmp_path / "PWNED")
    dk = WRITERS[engine](_renamed(case, text))
    ok = WRITERS[engine](_renamed(case, "benign"))
    assert_same_commands(dk.text, ok.text, "shell touch")
    assert_same_data(dk.files, ok.files)


@pytest.mark.parametrize("kind", sorted(HOSTILE))
@pytest.mark.parametrize("engine", ENGINES)
def test_packing_decks_keep_a_hostile_name_in_comments(kind, engine, tmp_path):
    case = _packing_case()
    text = hostile(kind, tmp_path / "PWNED")
    dk = PACKING_WRITERS[engine](_renamed(case, text))
    ok = PACKING_WRITERS[engine](_renamed(case, "benign"))
    assert_same_commands(dk.text, ok.text, "shell touch")
    assert_same_data(dk.files, ok.files)


@pytest.mark.parametrize("kind", sorted(HOSTILE))
@pytest.mark.parametrize("engine", ENGINES)
def test_mapping_comments_and_reasons_stay_comments(kind, engine, tmp_path, monkeypatch):
    """Free text of the mapping (the native configuration's comments, the fidelity reasons) goes into
    comment lines through the same helper."""
    case = _collision_case(True)
    text = hostile(kind, tmp_path / "PWNED")
    nat = mapping.contact_mapping(case, engine).native
    real = mapping.map_model

    def with_reason(reason):
        def patched(*args, **kw):
            mp = real(*args, **kw)
            return dataclasses.replace(mp, reasons=[*mp.reasons, reason])
        return patched

    monkeypatch.setattr(mapping, "map_model", with_reason(text))
    dk = WRITERS[engine](case)
    monkeypatch.setattr(mapping, "map_model", with_reason("benign"))
    ok = WRITERS[engine](case)
    assert_same_commands(dk.text, ok.text, "shell touch")
    monkeypatch.setattr(mapping, "map_model", real)
    dk = WRITERS[engine](case, native=dataclasses.replace(nat, comments=[text, "y " + text]))
    ok = WRITERS[engine](case, native=dataclasses.replace(nat, comments=["benign", "y"]))
    assert_same_commands(dk.text, ok.text, "shell touch")


@pytest.mark.parametrize("engine", ENGINES)
def test_material_names_never_reach_a_command_line(engine, tmp_path):
    case = _collision_case(False)
    name = hostile("newline", tmp_path / "PWNED")
    mats = {name: dataclasses.replace(case.materials["glass"], name=name)}
    parts = tuple(dataclasses.replace(p, material=name) for p in case.particles)
    dk = WRITERS[engine](dataclasses.replace(case, materials=mats, particles=parts))
    ok = WRITERS[engine](case)
    assert_same_commands(dk.text, ok.text, "shell touch")


def test_the_comment_helper_makes_one_printable_line():
    for kind in HOSTILE:
        line = common.comment(hostile(kind, Path("F")))
        assert line.startswith("#") and "\n" not in line
        assert_safe(line)
    assert common.comment("hertz k = (4/3)Ē, √R̄ δ^3/2 — m̄") == "# hertz k = (4/3)Ē, √R̄ δ^3/2 — m̄"


# ----------------------------------------------------------------------------- the final guard


INJECTED = ["shell touch F", "python f here \"\"\"", "include other.in", "jump SELF loop", "label loop",
            "print hello", "variable a string ${x}", "variable a python f", "fix p all print 1 hello",
            "fix p all python/invoke 1 end_of_step f", "compute c all reduce sum x", "dump d all image 1 a.jpg",
            "units si &", "# a comment &", "# \"\"\"", "run 10\rshell touch F", "set atom 1 mass ${m}",
            "run $(1000)", "  shell touch F", "clear", "quit", "partition yes 1 shell touch F", "log /tmp/x",
            "write_restart r", "write_data d", "next a", "if 1 then \"shell touch F\"",
            "run 10 every 1 \"shell touch F\"",
            "timestep 1e-8\u2028shell touch F", "pair_style python 1.0", "fix p all python/move f.py",
            "region r python f", "thermo_style python", "atom_style template t"]


@pytest.mark.parametrize("engine", ENGINES)
@pytest.mark.parametrize("line", INJECTED)
def test_the_guard_refuses_any_line_demcheck_does_not_write(engine, line):
    base = WRITERS[engine](_collision_case(False))
    lines = base.text.split("\n")
    at = lines.index(next(x for x in lines if x.startswith("units")))
    text = "\n".join(lines[:at] + [line] + lines[at:])
    with pytest.raises(DemcheckError):
        FD.check_deck(text)
    with pytest.raises(DemcheckError):
        common.Deck(engine, text, base.files, check=FD.check_deck)


def test_the_guard_refuses_a_data_file_with_more_than_its_title():
    base = WRITERS["liggghts"](_collision_case(False))
    name, data = next(iter(base.files.items()))
    with pytest.raises(DemcheckError):
        common.Deck("liggghts", base.text, {name: "# title\nshell touch F\n" + data.split("\n", 1)[1]},
                    check=FD.check_deck)


@pytest.mark.parametrize("engine", ENGINES)
def test_every_deck_demcheck_writes_passes_the_guard(engine):
    for path in sorted(CASES.glob("*.toml")) + sorted((CASES / "suite").glob("*.toml")):
        for case in C.expand(path):
            try:
                dk = WRITERS[engine](case)
            except DemcheckError:  # a model the engine cannot express
                continue
            FD.check_deck(dk.text)
    for path in sorted((CASES / "packing").glob("*.toml")):
        case = C.load(path)
        FD.check_deck(PACKING_WRITERS[engine](case).text)


# ----------------------------------------------------------------------------- end to end


def demcheck(*args, cwd):
    return subprocess.run([sys.executable, "-m", "demcheck", *map(str, args)], capture_output=True, text=True,
                          cwd=cwd, timeout=300)


def _assert_refused(p, f: Path):
    assert p.returncode == 2, (p.returncode, p.stderr[-2000:])
    lines = p.stderr.strip("\n").split("\n")
    assert len(lines) == 1 and lines[0].startswith("demcheck: error: "), p.stderr[-2000:]
    assert not f.exists()


@pytest.mark.parametrize("command", [("deck", "--engine", "lammps"), ("deck", "--engine", "liggghts"),
                                     ("collide",), ("collide", "--engine", "lammps"),
                                     ("collide", "--engine", "liggghts"), ("verify", "--engines", "none")])
def test_the_command_line_refuses_a_hostile_name_before_any_work(command, tmp_path):
    f = tmp_path / "PWNED"
    path = tmp_path / "case.toml"
    path.write_text(_case_text(f"name = {_toml_string(hostile('newline', f))}"))
    extra = ("--report", tmp_path / "reports") if command[0] == "verify" else ()
    _assert_refused(demcheck(command[0], path, *command[1:], *extra, cwd=tmp_path), f)
    assert not (tmp_path / "reports").exists()


@pytest.mark.parametrize("engine", ENGINES)
def test_the_command_line_refuses_a_hostile_name_through_set(engine, tmp_path):
    f = tmp_path / "PWNED"
    for case in (CASES / "glass-pair.toml", CASES / "packing" / "column-lsd.toml"):
        p = demcheck("deck", case, "--engine", engine, "--set", f"name={_toml_string(hostile('newline', f))}",
                     "-o", tmp_path / "in.deck", cwd=tmp_path)
        _assert_refused(p, f)
        assert not (tmp_path / "in.deck").exists()


def test_verify_refuses_a_hostile_variant_label(tmp_path):
    f = tmp_path / "PWNED"
    path = tmp_path / "case.toml"
    path.write_text(_case_text('name = "v"', '\n[variants]\n"contact.normal" = ["hertz", '
                               f'{_toml_string(hostile("newline", f))}]\n'))
    _assert_refused(demcheck("verify", path, "--engines", "lammps,liggghts", "--report", tmp_path / "reports",
                             cwd=tmp_path), f)


def _strongest(f: Path) -> list[str]:
    """Every hostile string, and all of them at once: what gets past the case validation only when a writer
    is fed directly (each one alone creates the file when written unescaped)."""
    texts = [hostile(kind, f) for kind in HOSTILE if kind != "long"]
    return texts + ["x &\nshell touch {f} &\r\nshell touch {f}\u2028shell touch {f}\x85shell touch {f} "
                    "\"\"\"\nshell touch {f}\n\"\"\" ${{f}} &".format(f=f)]


@pytest.mark.parametrize("engine", [pytest.param(e, marks=pytest.mark.engine(e)) for e in ENGINES])
def test_the_engines_run_the_deck_of_the_strongest_string_and_create_nothing(engine, tmp_path):
    from demcheck.engines import discovery

    f = tmp_path / "PWNED"
    texts = _strongest(f)
    work = tmp_path / "run"
    case = _renamed(_collision_case(True), texts[0])
    nat = mapping.contact_mapping(case, engine).native
    decks = {"in.deck": WRITERS[engine](case, native=dataclasses.replace(nat, comments=[*texts, *nat.comments])),
             "in.packing": PACKING_WRITERS[engine](_renamed(_packing_case(), texts[0]), duration=1e-3)}
    for name, dk in decks.items():
        dk.write(work / name)
        p = subprocess.run([discovery.find(engine).executable, "-in", name], cwd=work, capture_output=True,
                           text=True, timeout=300)
        assert not f.exists(), name
        assert p.returncode == 0, p.stdout[-2000:]
    assert (work / common.DUMP_FILE).exists() and (work / packing_decks.FINAL_DUMP).exists()


# ----------------------------------------------------------------------------- file modes


@pytest.fixture
def umask():
    """Restores the process's umask after a test that sets its own."""
    old = os.umask(0o022)
    os.umask(old)
    yield
    os.umask(old)


@pytest.mark.parametrize("mask,mode", [(0o022, 0o644), (0o077, 0o600), (0o002, 0o664), (0o000, 0o666)])
def test_written_files_honour_the_umask(mask, mode, tmp_path, umask):
    from demcheck import io

    os.umask(mask)
    io.write_text(tmp_path / "report.txt", "x\n")
    io.write_json(tmp_path / "a" / "summary.json", {"a": 1})
    with io.atomic_path(tmp_path / "table.csv") as tmp:
        Path(tmp).write_text("a,b\n")
    written = WRITERS["liggghts"](_collision_case(False)).write(tmp_path / "deck" / "in.deck")
    for path in [tmp_path / "report.txt", tmp_path / "a" / "summary.json", tmp_path / "table.csv", *written]:
        assert (path.stat().st_mode & 0o777) == mode, (path, oct(path.stat().st_mode))
    io.write_text(tmp_path / "report.txt", "y\n")  # replaced: the new file's mode
    assert (tmp_path / "report.txt").stat().st_mode & 0o777 == mode
    assert not [p for p in tmp_path.rglob(".*.tmp")]


def test_the_command_line_writes_decks_reports_and_junit_by_the_umask(tmp_path):
    import shlex

    def run(*args):
        command = shlex.join([sys.executable, "-m", "demcheck", *map(str, args)])
        p = subprocess.run(["sh", "-c", f"umask 022 && exec {command}"], capture_output=True, text=True, cwd=ROOT,
                           timeout=600)
        assert p.returncode == 0, p.stderr[-2000:]

    run("deck", CASES / "glass-pair.toml", "--engine", "liggghts", "-o", tmp_path / "in.deck")
    run("verify", CASES / "glass-pair.toml", "--engines", "none", "--report", tmp_path / "reports", "--junit",
        tmp_path / "junit.xml")
    written = [tmp_path / "in.deck", tmp_path / "data.lmp", tmp_path / "junit.xml",
               *[p for p in (tmp_path / "reports").rglob("*") if p.is_file() and not p.is_symlink()]]
    assert len(written) > 5
    for path in written:
        assert path.stat().st_mode & 0o777 == 0o644, path


def test_the_runner_refuses_a_deck_with_a_command_demcheck_does_not_write(tmp_path):
    """The last line of defence: whatever built the deck, engines.run checks it before any engine starts."""
    from demcheck.engines import run as runner
    from demcheck.errors import DemcheckError

    target = tmp_path / "pwned"
    for engine in ("lammps", "liggghts"):
        with pytest.raises(DemcheckError, match="not a command demcheck writes"):
            runner.run(engine, f"units si\nshell touch {target}\n", workdir=tmp_path / engine)
        assert not target.exists() and not (tmp_path / engine / "in.deck").exists()


@pytest.mark.parametrize("line", [
    'units si "#" $(1+1)',                              # a "#" inside quotes is no comment to LAMMPS
    'fix 1 all nve/sphere "#" ${x}',
    "fix 1 all nve/sphere # trailing text",
    "dump d all custom 1 /home/x/.bashrc id",           # a file outside the work directory
    "dump d all custom 1 ../dump.txt id",
    "write_dump all custom /tmp/x id",
    "write_dump all atom dump.txt",
    "read_data /etc/passwd",
])
def test_the_guard_refuses_hidden_comments_variables_and_paths(line):
    with pytest.raises(DemcheckError):
        FD.check_deck(f"units si\n{line}\n")


def test_a_comment_never_carries_a_triple_quote():
    for text in ['"""', '""""" tail', 'a"b""c"""d']:
        line = common.comment(text)
        assert '"""' not in line and line.startswith("# ")
        FD.check_deck(line + "\nunits si\n")


@pytest.mark.parametrize("engine", ["yade", "kratos"])
@pytest.mark.parametrize("name", ["x coding:raw_unicode_escape", "x coding=latin-1", "x -*- coding: utf-7 -*-"])
def test_a_python_deck_cannot_be_given_a_source_encoding(engine, name, tmp_path):
    """Yade's and Kratos' decks are Python scripts: Python decodes one by the encoding its first two lines may
    declare (PEP 263), so a case name carrying `coding:` in the deck's comment would make Python run a different
    text from the one the guard checked. Either the deck is refused (one line, exit 2, nothing written) or its first
    two lines declare no encoding (Yade's are fixed)."""
    import re
    import tokenize

    out = tmp_path / "d" / "in.deck"
    p = subprocess.run([sys.executable, "-m", "demcheck", "deck", str(CASES / "hertz-wall.toml"), "--engine", engine,
                        "--set", f'name="{name}"', "-o", str(out)], capture_output=True, text=True, timeout=300)
    if p.returncode == 2:
        assert p.stderr.strip().count("\n") == 0 and not out.exists(), p.stderr
    else:
        assert p.returncode == 0, p.stderr
        assert not any(re.search(r"coding[:=]", line) for line in out.read_text().split("\n")[:2])
        with out.open("rb") as f:
            assert tokenize.detect_encoding(f.readline)[0] == "utf-8"

"""A contact is slots (laws/base.py): every law is a record of one slot with named fields and a coefficient layout,
the kernels' laws are exactly their records (both ways), and the engines' vocabularies map the records by id —
never by the kernels' exponents or family numbers."""

from __future__ import annotations

import ast
import copy
import dataclasses
import tomllib
from pathlib import Path
from typing import ClassVar

import numpy as np
import pytest

from demcheck.case import apply_overrides, from_dict
from demcheck.engines import mapping, registry
from demcheck.laws import base, damping, normal, tangential
from demcheck.laws.model import resolve

SRC = Path(__file__).resolve().parents[1] / "src" / "demcheck"


def _combos():
    out = [(n, "none", {}) for n in normal.REGISTRY]
    out += [(mapping._PARTNER.get(t, "lsd"), t, {}) for t in tangential.REGISTRY if t != "none"]
    return out + mapping._VARIANTS + [("tti", "tti", {"eta_n": 0.0}), ("kk", "none", {"eta_n": 0.0})]


def _model(nid, tid, extra):
    raw = tomllib.loads(mapping._TABLE_CASE)
    params = {**normal.REGISTRY[nid].example, **tangential.REGISTRY[tid].example, **extra}
    params.pop("friction", None)
    sets = [f"contact.normal={nid}", f"contact.tangential={tid}"]
    sets += [f"contact.{k}={mapping._toml(v)}" for k, v in params.items()]
    return resolve(from_dict(apply_overrides(copy.deepcopy(raw), sets)))


@pytest.mark.parametrize("nid,tid,extra", _combos(), ids=lambda v: v if isinstance(v, str) else "")
def test_every_seed_model_is_its_records_both_ways(nid, tid, extra):
    model = _model(nid, tid, extra)
    contact = model.contact
    assert [slot for slot, _ in contact.slots()] == list(base.SLOTS)
    assert {contact.rolling.id, contact.twisting.id, contact.adhesion.id, contact.heat.id} == {"none"}
    assert normal.NormalLaw.from_slots(contact.normal, contact.damping, model.limit_force) == model.normal_law
    assert tangential.TangentialLaw.from_slot(contact.tangential) == model.tangential_law
    for _, record in contact.slots():
        assert type(record).from_array(record.array()) == record
        assert record.array().dtype == np.float64 and record.array().shape == (len(record.param_names()),)


def test_every_engine_twin_is_its_records_both_ways():
    """What the engines compute (their twins) is expressed in the same records."""
    seen = 0
    for nid, tid, extra in _combos():
        model = _model(nid, tid, extra)
        for engine in registry.names():
            mp = mapping.map_model(model, engine, {})
            if mp.native is None:
                continue
            nl, tl = registry.get(engine).twin(mp.native, model.pair.m_eff, model.pair.r_eff)
            n_rec, d_rec = nl.slots()
            assert normal.NormalLaw.from_slots(n_rec, d_rec, nl.limit) == nl
            assert tangential.TangentialLaw.from_slot(tl.slot()) == tl
            seen += 1
    assert seen > 20


def test_the_records_name_what_the_old_numbers_meant():
    assert normal.NormalLaw(normal.VISCOELASTIC, k=2.0, a=1.5, eta=3.0, b=0.25).slots() == (
        normal.HertzNormal(k=2.0), damping.QuarterDamping(eta=3.0))
    assert normal.NormalLaw(normal.VISCOELASTIC, k=2.0, a=1.0).slots() == (normal.HookeNormal(k=2.0),
                                                                           damping.NoDamping())
    assert normal.NormalLaw(normal.HYSTERETIC, kl=5.0, ku=7.0).slots()[0] == normal.HysteresisNormal(kl=5.0, ku=7.0)
    assert tangential.TangentialLaw(tangential.SPRING, kt=1.0, kt_sqrt=True).slot().id == "sqrt_spring"
    assert tangential.TangentialLaw(tangential.SPRING, kt=1.0).slot().id == "spring"
    with pytest.raises(ValueError, match="δ\\^2 spring"):
        normal.NormalLaw(normal.VISCOELASTIC, k=1.0, a=2.0).slots()
    with pytest.raises(ValueError, match="δ\\^0.75 dashpot"):
        normal.NormalLaw(normal.VISCOELASTIC, k=1.0, a=1.0, eta=1.0, b=0.75).slots()
    with pytest.raises(ValueError, match="no field for kt"):
        tangential.TangentialLaw(tangential.SLIDING, kt=1.0).slot()


def test_history_sizes_and_offsets_follow_the_slots():
    contact = base.Contact(normal.HysteresisNormal(kl=1.0), damping.NoDamping(),
                           tangential.WaltonTangential(k0=1.0))
    assert contact.history_size == 1 + 9
    assert contact.history_offsets() == {"normal": 0, "damping": 1, "tangential": 1, "rolling": 10,
                                         "twisting": 10, "adhesion": 10, "heat": 10}
    with pytest.raises(ValueError, match="contact slot 'damping' holds"):
        base.Contact(normal.HookeNormal(k=1.0), tangential.NoTangential(), tangential.NoTangential())


def test_a_slot_and_id_is_registered_once():
    assert base.sub_model("damping", "quarter") is damping.QuarterDamping
    assert "sqrt_spring" in base.ids("tangential")
    with pytest.raises(ValueError, match="registered twice"):
        @dataclasses.dataclass(frozen=True)
        class Again(base.SubModel):
            slot: ClassVar[str] = "damping"
            id: ClassVar[str] = "quarter"
    with pytest.raises(ValueError, match="is not one of"):
        @dataclasses.dataclass(frozen=True)
        class Nowhere(base.SubModel):
            slot: ClassVar[str] = "sideways"
            id: ClassVar[str] = "x"
    with pytest.raises(KeyError, match="no rolling sub-model 'no_such_law'"):  # (epsd is a rolling law now)
        base.sub_model("rolling", "no_such_law")


# the kernels' numbers that name a law: an engine's vocabulary reads record ids instead
_KERNEL_NAMES = {"HYSTERETIC", "VISCOELASTIC", "NONE", "SLIDING", "VISCOUS", "VISCOUS_SLIDING", "SPRING", "LTH",
                 "ZZY", "WALTON"}
_KERNEL_ATTRIBUTES = {"normal_law", "tangential_law", "family", "kt_sqrt", "a", "b"}


@pytest.mark.parametrize("path", sorted((SRC / "engines").glob("*/mapping.py")), ids=lambda p: p.parent.name)
def test_engines_map_records_never_exponents_or_families(path):
    """Every function of an engine's vocabulary but its twin (settings → kernel laws) reads the contact's slot
    records: no kernel family constant, no exponent, no law array."""
    bad = []
    for fn in ast.walk(ast.parse(path.read_text())):
        if not isinstance(fn, ast.FunctionDef) or fn.name.startswith("twin") or fn.name == "law":
            continue
        for node in ast.walk(fn):
            if isinstance(node, ast.Name) and node.id in _KERNEL_NAMES:
                bad.append(f"{fn.name}:{node.lineno}: {node.id}")
            if isinstance(node, ast.Attribute) and node.attr in _KERNEL_ATTRIBUTES:
                bad.append(f"{fn.name}:{node.lineno}: .{node.attr}")
    assert not bad, "\n".join(bad)


def test_an_engine_refuses_a_record_it_cannot_express_by_its_id():
    """A Hertz spring with a constant dashpot (no seed model pairs them): LAMMPS has no damping style for it and
    says which dashpot; LIGGGHTS names the normal model."""
    model = _model("kk", "none", {})
    law = normal.NormalLaw.from_slots(normal.HertzNormal(k=model.normal_law.k), damping.ConstantDamping(eta=3.0),
                                      False)
    odd = dataclasses.replace(model, normal_law=law)
    assert odd.contact.damping.id == "constant"
    lammps = mapping.map_model(odd, "lammps", {})
    assert lammps.fidelity == "none" and "δ^0 law" in lammps.reasons[0]
    assert mapping.map_model(odd, "liggghts", {}).fidelity == "none"


@pytest.mark.parametrize("nid,tid,extra", _combos(), ids=lambda v: v if isinstance(v, str) else "")
def test_the_kernels_tangential_array_reads_back_exactly(nid, tid, extra):
    tl = _model(nid, tid, extra).tangential_law
    assert tangential.TangentialLaw.from_array(tl.array()) == tl


def test_the_packing_rows_are_as_wide_as_the_records_histories():
    """The packing's contact-state row: the widest record history (Walton 9, a displacement 3, at least 3), and a
    spring's slip state where μk < μs."""
    from demcheck.reference.packing import history_width

    spring = tangential.SpringTangential(kt=1.0, mu_s=0.5, mu_k=0.5)
    assert history_width([tangential.NoTangential()]) == 3
    assert history_width([spring, tangential.LthTangential()]) == 3
    assert history_width([dataclasses.replace(spring, mu_k=0.4)]) == 4
    assert history_width([dataclasses.replace(spring, mu_k=0.4), tangential.WaltonTangential(k0=1.0)]) == 9


@dataclasses.dataclass(frozen=True)
class _TestOnlyNormal(normal.NormalSubModel):
    """A normal record no engine knows (registered by this test module only)."""

    id: ClassVar[str] = "test_only_cubic"
    k: float = 0.0


@dataclasses.dataclass(frozen=True)
class _TestOnlyTangential(tangential.TangentialSubModel):
    id: ClassVar[str] = "test_only_glue"
    history_size: ClassVar[int] = 2
    c: float = 0.0


@pytest.mark.parametrize("slot", ["normal", "tangential"])
@pytest.mark.parametrize("engine", registry.names())
def test_a_record_an_engine_does_not_know_is_refused(engine, slot):
    """A new law's record reaches every engine's vocabulary, which refuses what it has no branch for — with no
    edit to the engine (never mistaken for a known record of the same shape)."""
    model = _model("lsd", "none", {})
    contact = model.contact
    new = dataclasses.replace(contact, normal=_TestOnlyNormal(k=1e6)) if slot == "normal" else \
        dataclasses.replace(contact, tangential=_TestOnlyTangential(c=1.0))
    odd = dataclasses.replace(model)
    odd.__dict__["contact"] = new  # the cached slots of this model (ResolvedModel.contact)
    assert mapping.map_model(odd, engine, {}).fidelity == "none"
    assert new.history_size == contact.history_size + (2 if slot == "tangential" else 0)

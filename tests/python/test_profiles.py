"""Profiles, the planner's path, the object table and the package's vocabulary."""
import pathlib
import re

import pytest

import cia402


def test_version_is_the_projects(source_dir):
    cmake = (source_dir / "CMakeLists.txt").read_text()
    assert cia402.__version__ == re.search(r"project\(cia402 VERSION (\S+)", cmake).group(1)


def test_the_builtin_profiles_and_the_states():
    assert cia402.profiles() == ["cia402", "no-quick-stop", "lexium32", "s300-profibus", "ax2000-profibus"]
    assert cia402.states() == ["NOT_READY_TO_SWITCH_ON", "SWITCH_ON_DISABLED", "READY_TO_SWITCH_ON",
                               "SWITCHED_ON", "OPERATION_ENABLED", "QUICK_STOP_ACTIVE",
                               "FAULT_REACTION_ACTIVE", "FAULT"]


def test_a_builtin_profile_describes_itself():
    p = cia402.Profile("cia402")
    assert p.name == "cia402" and p.builtin and not p.error_classes
    assert p.options[0x605A] == {"default": 2, "values": list(range(9))}
    assert set(p.options) == {0x605A, 0x605B, 0x605C, 0x605D, 0x605E, 0x6007}
    assert p.transitions[0] == 13  # every built-in table lists T13 first: a fault beats any command
    assert cia402.Profile("lexium32").error_classes
    assert repr(p) == "cia402.Profile('cia402')"


@pytest.mark.parametrize("name", cia402.profiles())
def test_a_profile_written_as_toml_loads_back_to_the_same_tables(name):
    p = cia402.Profile(name)
    again = cia402.Profile.from_toml(p.to_toml(), "dump")
    assert not again.builtin and again.name == p.name
    assert again.to_toml() == p.to_toml() and again.transitions == p.transitions and again.options == p.options


def test_a_bad_profile_text_is_refused_with_line_and_column():
    with pytest.raises(cia402.ProfileError) as refused:
        cia402.Profile.from_toml('base = "cia402"\nname = 5\n', "mine.toml")
    e = refused.value
    assert (e.line, e.source) == (2, "mine.toml") and e.column > 0 and e.reason
    assert isinstance(e, cia402.FileError) and isinstance(e, cia402.Error)
    with pytest.raises(cia402.ProfileError) as missing:
        cia402.Profile.from_file("/nonexistent/profile.toml")
    assert missing.value.line == 0


def test_path_from_switch_on_disabled_to_operation_enabled():
    steps = cia402.path("SWITCH_ON_DISABLED", "OE")
    assert [(s.control_word, s.transition, s.state) for s in steps] == [
        (0x06, 2, "READY_TO_SWITCH_ON"), (0x0F, 3, "SWITCHED_ON"), (0x0F, 4, "OPERATION_ENABLED")]
    assert steps[0].command == "SHUTDOWN" and steps[2].command == "ENABLE_OPERATION"
    assert "SHUTDOWN" in repr(steps[0])


def test_path_from_fault_resets_on_an_edge():
    steps = cia402.path("F", "SOD")
    assert steps[-1].control_word & 0x80 and steps[-1].transition == 15
    assert steps[-1].command.startswith("FAULT_RESET + ")


def test_path_never_enables_motion_on_the_way_to_another_state():
    for target in cia402.states():
        for start in cia402.states():
            steps = cia402.path(start, target, options={0x605A: 6})
            if steps is None or "OPERATION_ENABLED" in (start, target):
                continue
            assert "OPERATION_ENABLED" not in [s.state for s in steps], (start, target)


def test_path_already_there_is_empty_and_unreachable_is_none():
    assert cia402.path("OE", "OE") == []
    assert cia402.path("SOD", "QSA", profile="no-quick-stop") is None
    # QUICK STOP ACTIVE is entered from OPERATION ENABLED only, and a path to it never enables
    # motion on the way (S17): from SWITCH ON DISABLED there is none.
    assert cia402.path("SOD", "QUICK_STOP_ACTIVE", profile=cia402.Profile("cia402")) is None
    assert [s.transition for s in cia402.path("OE", "QSA", profile=cia402.Profile("cia402"))] == [11]


def test_path_refuses_an_unknown_state_and_a_bad_option():
    with pytest.raises(cia402.ArgumentError, match="OPERATION_ENABLED \\(OE\\)"):
        cia402.path("SOD", "ENABLED")
    with pytest.raises(cia402.SdoError):
        cia402.path("SOD", "OE", options={0x605A: 42})


def test_the_object_table():
    table = {(o["index"], o["sub"]): o for o in cia402.objects()}
    target = table[(0x607A, 0)]
    assert target["name"] == "Target position" and target["type"] == "INTEGER32" and target["access"] == "rw"
    assert table[(0x6041, 0)]["access"] == "ro" and table[(0x60FF, 0)]["unit"] == "rpm"


def test_sdo_abort_texts():
    assert cia402.sdo_abort_text(0x06020000) == "object does not exist in the object dictionary"
    assert cia402.sdo_abort_text(0x06010002) == "attempt to write a read only object"

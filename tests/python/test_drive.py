"""cia402.Drive: the core on an ideal plant (inputs by keyword) or on the simulator's plant."""
import pytest

import cia402

SOD, RTSO, SO, OE = "SWITCH_ON_DISABLED", "READY_TO_SWITCH_ON", "SWITCHED_ON", "OPERATION_ENABLED"


def enabled(profile="cia402"):
    d = cia402.Drive(profile)
    d.settle()
    d.settle(control_word=0x06)
    d.settle(control_word=0x0F)
    return d


def test_power_up_takes_t0_then_t1_one_step_each():
    d = cia402.Drive()
    first = d.step()
    assert (first.state, first.transitions, first.transition) == ("NOT_READY_TO_SWITCH_ON", [0], 0)
    second = d.step()
    assert (second.state, second.transitions) == (SOD, [1])
    third = d.step()
    assert (third.state, third.transitions, third.transition) == (SOD, [], None)


def test_enable_operation_in_ready_to_switch_on_takes_t3_then_t4_and_status_0x0237():
    d = cia402.Drive()
    d.settle()
    assert d.step(control_word=0x06).transitions == [2]
    out = d.step(control_word=0x0F)
    assert (out.state, out.transitions) == (SO, [3])
    out = d.step()  # the control word holds: no need to give it again
    assert (out.state, out.transitions, out.status_word) == (OE, [4], 0x0237)
    assert out.torque and out.brake == "released" and out.brake_released and out.ramp == "none"
    assert d.state == OE and d.status_word == 0x0237 and d.inputs["control_word"] == 0x0F


def test_settle_lists_every_transition_and_reports_it_came_to_rest():
    d = cia402.Drive()
    power_up = d.settle()
    assert power_up.transitions == [0, 1] and power_up.settled
    out = d.settle(control_word=0x06)
    assert (out.state, out.transitions) == (RTSO, [2])
    out = d.settle(control_word=0x0F)
    assert (out.state, out.transitions, out.settled) == (OE, [3, 4], True)


def test_quick_stop_with_code_6_stays_in_quick_stop_active_and_t16_enables_again():
    d = enabled()
    d[0x605A] = 6
    out = d.settle(control_word=0x02)
    assert (out.state, out.transitions) == ("QUICK_STOP_ACTIVE", [11])
    assert out.status_word & 0x0400  # bit 10 at standstill (S5)
    assert d.settle(control_word=0x0F).transitions == [16]


def test_quick_stop_with_default_code_2_ends_in_switch_on_disabled():
    d = enabled()
    out = d.settle(control_word=0x02)
    assert (out.state, out.transitions) == (SOD, [11, 12])


def test_fault_then_reset_on_the_rising_edge_of_bit_7_only_once_the_cause_is_gone():
    d = enabled()
    out = d.settle(fault=0x2310)
    assert (out.state, out.transitions, out.error_code) == ("FAULT", [13, 14], 0x2310)
    assert not out.torque and out.brake == "engaged"
    assert d.error_code == 0x2310 and d[0x603F] == 0x2310 and d[0x1001] == 0x03
    assert d.settle(control_word=0x80).transitions == []  # the cause is still there (S2)
    d.settle(fault=0, control_word=0x00)
    out = d.settle(control_word=0x80)
    assert (out.state, out.transitions) == (SOD, [15])


def test_sto_while_operation_enabled_removes_torque_at_once_and_is_a_fault():
    d = enabled()
    out = d.step(sto=True)
    assert not out.torque and out.state == "FAULT_REACTION_ACTIVE" and out.transitions == [13]


def test_dc_link_lost_in_ready_to_switch_on_blocks_t3():
    d = cia402.Drive()
    d.settle(control_word=0x06)
    assert d.settle(dc_link=False, control_word=0x0F).state == RTSO
    assert d.settle(dc_link=True).transitions == [3, 4]


def test_inputs_keep_their_value_and_are_reported():
    d = cia402.Drive()
    d.step(control_word=0x06, standstill=False, actual_speed_rpm=-12, status_bits=0x0400)
    d.step()
    inputs = d.inputs
    assert inputs["control_word"] == 0x06 and inputs["standstill"] is False
    assert inputs["actual_speed_rpm"] == -12 and inputs["status_bits"] == 0x0400
    assert set(inputs) == {"control_word", "dc_link", "sto", "fault", "fault_class", "standstill",
                           "brake_engaged", "remote", "connection_lost", "local_enable",
                           "local_disable", "status_bits", "actual_speed_rpm"}


def test_an_input_out_of_range_is_refused_and_changes_nothing():
    d = cia402.Drive()
    d.settle(control_word=0x06)
    before = d.inputs
    with pytest.raises(cia402.ArgumentError, match="control_word 65536"):
        d.step(control_word=0x10000, sto=True)
    with pytest.raises(cia402.ArgumentError, match="fault_class"):
        d.step(fault=0x1000, fault_class=5)
    assert d.inputs == before and d.state == RTSO
    with pytest.raises(TypeError):
        d.step(contol_word=6)  # a misspelt input is no input
    with pytest.raises(TypeError):
        d.step(6)  # keywords only


def test_inputs_take_their_own_types_and_none_leaves_an_input_as_it_is():
    d = cia402.Drive()
    d.settle(control_word=0x06)
    with pytest.raises(TypeError, match="sto takes True or False"):
        d.step(sto=1)
    with pytest.raises(TypeError, match="control_word takes an int"):
        d.step(control_word=6.0)
    assert d.step(control_word=None, sto=None).state == RTSO and d.inputs["control_word"] == 0x06
    numpy = pytest.importorskip("numpy")
    assert d.settle(control_word=numpy.int64(0x0F)).transitions == [3, 4]  # anything with __index__


def test_option_codes_are_written_and_read_by_index():
    d = cia402.Drive()
    assert d[0x605A] == 2 and d.read(0x605E) == 2
    d[0x605A] = 5
    d.write(0x605E, 0)
    assert d[0x605A] == 5 and d[0x605E] == 0


def test_an_unsupported_option_value_raises_sdo_error_with_its_abort_code_and_changes_nothing():
    d = cia402.Drive()
    with pytest.raises(cia402.SdoError) as refused:
        d[0x605A] = 9
    assert refused.value.code == 0x06090030
    assert refused.value.text == cia402.sdo_abort_text(0x06090030) == "invalid value for parameter"
    assert refused.value.index == 0x605A and refused.value.sub == 0
    assert "0x06090030" in str(refused.value) and "0x605A" in str(refused.value)
    assert d[0x605A] == 2


@pytest.mark.parametrize("key, value, code", [
    (0x6060, 8, 0x06020000),           # no such object on an ideal drive
    (0x6041, 0, 0x06010002),           # read-only status word
    ((0x605A, 1), 6, 0x06090011),      # no sub-index 1
    (0x6040, 0x10000, 0x06090031),     # beyond 16 bits
    (0x605A, 2**31, 0x06090031),
    (0x605A, -(2**31) - 1, 0x06090032),
])
def test_refused_writes_carry_the_abort_code(key, value, code):
    d = cia402.Drive()
    with pytest.raises(cia402.SdoError) as refused:
        d[key] = value
    assert refused.value.code == code


def test_the_control_word_and_status_word_are_objects_too():
    d = cia402.Drive()
    d[0x6040] = 0x06
    d.settle()
    assert d.state == RTSO and d[0x6040] == 0x06 and d[0x6041] == d.status_word == 0x0231


def test_an_unknown_profile_is_a_profile_error_naming_the_built_ins():
    with pytest.raises(cia402.ProfileError, match="no-quick-stop") as refused:
        cia402.Drive("nope")
    assert refused.value.line == 0


def test_a_profile_file_runs_and_a_bad_one_is_refused_with_its_line(examples, tmp_path):
    d = cia402.Drive.from_file(str(examples / "profiles" / "custom-drive.toml"))
    assert d.profile.name == "custom-drive" and d[0x605A] == 6
    bad = tmp_path / "bad.toml"
    bad.write_text('base = "cia402"\nname = "x"\n[options.0x605A]\nsupported = [2, 6]\ndefualt = 6\n')
    with pytest.raises(cia402.ProfileError) as refused:
        cia402.Drive.from_file(str(bad))
    assert refused.value.line == 5 and "defualt" in refused.value.reason
    assert refused.value.source.endswith("bad.toml") and ":5:" in str(refused.value)


@pytest.mark.parametrize("profile", cia402.profiles())
def test_every_builtin_profile_reaches_operation_enabled_by_the_planners_words(profile):
    d = cia402.Drive(profile)
    d.settle()
    steps = d.path("OE")
    assert steps
    for s in steps:
        out = d.step(control_word=s.control_word)
        assert out.state == s.state and out.transition == s.transition
    assert d.state == OE and d.outputs.torque


def test_outputs_read_as_a_dict_and_a_repr():
    d = cia402.Drive()
    d.settle(control_word=0x06)
    out = d.settle(control_word=0x0F)
    assert d.outputs.transitions == [] and d.outputs.state == OE  # the last step: at rest
    assert out.as_dict() == {"state": OE, "status_word": 0x0237, "transitions": [3, 4],
                             "torque": True, "brake": "released", "ramp": "none", "error_code": 0}
    assert "OPERATION_ENABLED" in repr(out) and "0x0237" in repr(out)
    assert out.error_register == 0 and out.clear_setpoints in (True, False)


def test_a_drive_on_the_simulated_plant_ramps_its_motor_and_waits_for_its_brake():
    d = cia402.Drive(plant={"brake_release_delay_us": 5000})
    assert d.machine is not None and d.axis is not None and len(d.machine) == 1
    d.step(control_word=0x06)
    for _ in range(3):
        d.step()
    d.step(control_word=0x0F)
    d.step()
    assert d.state == OE
    d[0x60FF] = 600
    for _ in range(2000):
        d.step()
    assert d.axis.velocity_rpm == 600 and d[0x606C] == 600
    assert d.inputs["standstill"] is False
    out = d.step(sto=True)
    assert not out.torque and d.axis.sto


def test_the_simulated_plant_gives_its_own_feedback():
    d = cia402.Drive(plant=True)
    with pytest.raises(cia402.ArgumentError, match="standstill"):
        d.step(standstill=True)
    with pytest.raises(cia402.ArgumentError, match="ideal plant"):
        d.settle()
    with pytest.raises(cia402.ArgumentError, match="plant"):
        cia402.Drive(plant={"cycle_us": 0})


def test_a_fault_on_the_simulated_plant_is_one_cause_that_fault_0_clears():
    d = cia402.Drive(plant=True)
    d.step(fault=0x4310, fault_class=1)
    assert d.axis.fault_cause == 0x4310
    for _ in range(3):
        d.step()
    assert d.state == "FAULT" and d.error_code == 0x4310
    d.step(fault=0)
    assert d.axis.fault_cause == 0

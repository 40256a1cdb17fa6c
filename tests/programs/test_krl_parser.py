"""The KRL test parser on public KRL programs and on KUKA's documented syntax.

Excerpts (each at most 30 lines, elisions marked ``; [...]``, trailing blanks removed) of
ros-industrial/kuka_experimental (repository licence Apache-2.0; both files carry a BSD
licence header):
``kuka_rsi_hw_interface/krl/KR_C4/ros_rsi.src`` (NTNU, BSD-3-Clause) and
``kuka_eki_hw_interface/krl/kuka_eki_hw_interface.src`` / ``.dat`` (3M, BSD-3-Clause).
"""

from __future__ import annotations

import numpy as np
import pytest

from tests.programs.krl_parser import frame_pose, parse_krl, parse_tree

# kuka_experimental kuka_rsi_hw_interface/krl/KR_C4/ros_rsi.src, lines 1-5 and 52-69
# (BSD-3-Clause, Norwegian University of Science and Technology); the END line is added.
RSI_START = """&ACCESS RVP
&REL 4
&PARAM TEMPLATE = C:\\KRC\\Roboter\\Template\\vorgabe
&PARAM EDITMASK = *
DEF RSI_AxisCorr( )
; [...]
; Declaration of KRL variables
DECL INT ret\t; Return value for RSI commands
DECL INT CONTID\t; ContainerID

;FOLD INI
  ;FOLD BASISTECH INI
    GLOBAL INTERRUPT DECL 3 WHEN $STOPMESS==TRUE DO IR_STOPM ( )
    INTERRUPT ON 3
    BAS (#INITMOV,0 )
  ;ENDFOLD (BASISTECH INI)
  ;FOLD USER INI
    ;Make your modifications here

  ;ENDFOLD (USER INI)
;ENDFOLD (INI)

; Move to start position
PTP {A1 0, A2 -90, A3 90, A4 0, A5 90, A6 0}
END
"""

# the same file, lines 83-94, under a DEF line added for the test
RSI_END = """DEF RSI_AxisCorr_End( )
; [...]
; Sensor guided movement
RSI_MOVECORR()

; Turn off RSI
ret = RSI_OFF()
IF (ret <> RSIOK) THEN
  HALT
ENDIF

PTP {A1 0, A2 -90, A3 90, A4 0, A5 90, A6 0}

END
"""

# kuka_experimental kuka_eki_hw_interface/krl/kuka_eki_hw_interface.src, lines 2, 36-41
# and 62-78 (BSD-3-Clause, 3M)
EKI_MAIN = """def  kuka_eki_hw_interface()
; [...]
   ; Declarations
   decl axis joint_pos_tgt
   decl int elements_read

   ; INI
   bas(#initmov, 0)  ; Basic initializasion of axes
; [...]
   eki_hw_iface_init()

   ; BCO (Block COincidence) run to current position
   ; (requied for below loop continue before first incoming command)
   joint_pos_tgt = $axis_act_meas
   ptp joint_pos_tgt

   ; Loop forever
   $advance = 5
   loop
      elements_read = eki_hw_iface_get(joint_pos_tgt)  ; Get new command from buffer if present
      ptp joint_pos_tgt c_ptp                          ; PTP to most recent commanded position
   endloop

   ; Note: EKI channels delete on reset or deselect of this program
   ;       See <ENVIRONMENT>Program</ENVIRONMENT> EKI config element
end
"""

# the same file, lines 82-99 (a local subprogram)
EKI_INIT = """def eki_hw_iface_init()
   decl eki_status eki_ret

   ; Setup interrupts
   ; Interrupt 15 - Connection cleanup on client disconnect
   global interrupt decl 15 when $flag[1]==false do eki_hw_iface_reset()
   interrupt on 15
   ; Interrupt 16 - Timer interrupt for periodic state transmission
   global interrupt decl 16 when $timer_flag[1]==true do eki_hw_iface_send()
   interrupt on 16
   wait sec 0.012          ; Wait for next interpolation cycle
   $timer[1] = -200        ; Time in [ms] before first interrupt call
   $timer_stop[1] = false  ; Start timer 1

   ; Create and open EKI interface
   eki_ret = eki_init("EkiHwInterface")
   eki_ret = eki_open("EkiHwInterface")
end
"""

# kuka_experimental kuka_eki_hw_interface/krl/kuka_eki_hw_interface.dat (whole file)
EKI_DAT = """&ACCESS RVO
defdat kuka_eki_hw_interface
   ext bas(bas_command  :in,real  :in )
enddat
"""

# Written for these tests in the syntax of KUKA's KSS 8 manuals (inline-form data lists
# with FDAT/PDAT, Status and Turn as bit strings, spline blocks with WITH and C_SPL).
DOC_SRC = """&ACCESS RVP
&REL 1
DEF weld_demo( )
; documented-syntax example
;FOLD INI
  BAS (#INITMOV,0 )
;ENDFOLD (INI)
$BASE = {FRAME: X 1000.0, Y 0.0, Z 500.0, A 90.0, B 0.0, C 0.0}
$TOOL = {X 0.0, Y 0.0, Z 200.0, A 0.0, B -90.0, C 0.0}
$VEL_AXIS[1] = 50
PTP XHOME_AX C_PTP
$VEL.CP = 0.1
$APO.CDIS = 2.0
LIN XP1 C_DIS
CIRC XP2, XP3 C_DIS
SPLINE WITH $VEL = {CP 0.05}
  SLIN XP4
  SPL {X 10, Y 20, Z 30, A 0, B 90, C 0, S 'B110', T 'B100010'}
  SCIRC XP5, XP6
ENDSPLINE
PTP_SPLINE
  SPTP {A1 10, A2 -80, A3 95, A4 0, A5 30, A6 0} WITH $VEL_AXIS[1] = 40
ENDSPLINE C_SPL
END
"""

DOC_DAT = """&ACCESS RVP
&REL 1
DEFDAT weld_demo
EXT BAS (BAS_COMMAND :IN,REAL :IN )
DECL E6AXIS XHOME_AX={A1 0.0,A2 -90.0,A3 90.0,A4 0.0,A5 0.0,A6 0.0,E1 0.0,E2 0.0}
DECL FDAT FP1={TOOL_NO 1,BASE_NO 0,IPO_FRAME #BASE,POINT2[] " ",TQ_STATE FALSE}
DECL PDAT PPDAT1={VEL 100.0,ACC 100.0,APO_DIST 100.0,APO_MODE #CPTP}
DECL E6POS XP1={X 100.0,Y 0.0,Z 0.0,A 0.0,B 90.0,C 0.0,S 2,T 35,E1 0.0}
DECL E6POS XP2={X 150.0,Y 50.0,Z 0.0,A 0.0,B 90.0,C 0.0,S 2,T 35}
DECL E6POS XP3={X 200.0,Y 0.0,Z 0.0,A 0.0,B 90.0,C 0.0,S 2,T 35}
DECL E6POS XP4={X 250.0,Y 0.0,Z 0.0,A 0.0,B 90.0,C 0.0,S 6,T 50}
DECL POS XP5={X 300.0,Y 50.0,Z 0.0,A 0.0,B 90.0,C 0.0}
DECL POS XP6={X 350.0,Y 0.0,Z 0.0,A 0.0,B 90.0,C 0.0}
ENDDAT
"""


def test_rsi_program() -> None:
    start = parse_krl({"RSI_AxisCorr.src": RSI_START})
    end = parse_krl({"RSI_AxisCorr_End.src": RSI_END})
    assert start.name == "RSI_AxisCorr" and end.name == "RSI_AxisCorr_End"
    home = np.deg2rad([0, -90, 90, 0, 90, 0])
    for parsed in (start, end):
        assert [t.kind for t in parsed.targets] == ["joint"]
        np.testing.assert_allclose(parsed.targets[0].joints, home, atol=1e-12)
        assert parsed.targets[0].zone == 0.0 and parsed.targets[0].speed is None
    assert start.header == ["[...]", "Declaration of KRL variables"]


def test_eki_program_lower_case_and_local_subprogram() -> None:
    files = {
        "kuka_eki_hw_interface.src": EKI_MAIN + EKI_INIT,
        "kuka_eki_hw_interface.dat": EKI_DAT,
    }
    parsed = parse_krl(files)
    assert parsed.name == "kuka_eki_hw_interface"
    # both PTPs go to a variable set at run time: read as joint moves without values
    assert [(t.kind, t.joints, t.pose) for t in parsed.targets] == [("joint", None, None)] * 2
    assert parsed.targets[0].zone == 0.0 and parsed.targets[1].zone == 0.0  # no $APO.CDIS


def test_documented_syntax() -> None:
    parsed = parse_krl({"weld_demo.src": DOC_SRC, "weld_demo.dat": DOC_DAT})
    kinds = [t.kind for t in parsed.targets]
    assert kinds == [
        "joint",
        "linear",
        "circular_via",
        "circular_end",
        "linear",
        "spline",
        "circular_via",
        "circular_end",
        "joint",
    ]
    np.testing.assert_allclose(parsed.base[:3, 3], [1.0, 0.0, 0.5])
    np.testing.assert_allclose(parsed.base[:3, 0], [0.0, 1.0, 0.0], atol=1e-12)
    np.testing.assert_allclose(parsed.tool[:3, 2], [-1.0, 0.0, 0.0], atol=1e-12)
    home, lin, *_, spl, _, _, sptp = parsed.targets
    np.testing.assert_allclose(np.rad2deg(home.joints), [0, -90, 90, 0, 0, 0], atol=1e-9)
    assert home.speed == pytest.approx(0.5) and home.zone == 0.0  # C_PTP: no $APO.CDIS set yet
    assert lin.speed == pytest.approx(0.1) and lin.zone == pytest.approx(0.002)
    assert lin.config == {"S": 2, "T": 35}
    assert spl.config == {"S": 6, "T": 34}
    np.testing.assert_allclose(spl.pose[:3, 3], [0.01, 0.02, 0.03])
    assert sptp.speed == pytest.approx(0.4) and sptp.zone == pytest.approx(0.002)


def test_keywords_in_any_case() -> None:
    lower = parse_krl({"weld_demo.src": DOC_SRC.lower(), "weld_demo.dat": DOC_DAT.lower()})
    upper = parse_krl({"weld_demo.src": DOC_SRC, "weld_demo.dat": DOC_DAT})
    assert [t.kind for t in lower.targets] == [t.kind for t in upper.targets]
    for a, b in zip(lower.targets, upper.targets, strict=True):
        for x, y in ((a.pose, b.pose), (a.joints, b.joints)):
            assert (x is None) == (y is None)
            if x is not None:
                np.testing.assert_allclose(x, y)


def test_frame_pose_convention() -> None:
    """A, B, C turn about z, then the new y, then the new x (R = Rz(A) Ry(B) Rx(C))."""
    pose = frame_pose({"A": 90.0, "B": 0.0, "C": 90.0})
    np.testing.assert_allclose(pose[:3, :3], [[0, 0, 1], [1, 0, 0], [0, 1, 0]], atol=1e-12)


def test_syntax_error_is_reported() -> None:
    with pytest.raises(Exception, match="Unexpected"):
        parse_tree("DEF broken( )\nPTP {A1 0,, A2 1}\nEND\n")

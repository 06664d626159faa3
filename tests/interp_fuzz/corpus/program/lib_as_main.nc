' public.dat library used by the front-end tests: the custom M codes of S0 section 4.2 and the
' custom G86 with retract of S0 section 4.1.1 example 2, copied from the manual. O203 has one
' extra line, M03, to check that a custom code is not re-entered from its own subprogram (CUS-5).
'actions when the spindle speed is set (S0 labels it O202; see FEATURES CUS-4)
O203
M901 H2 P1
G04 P5
M03
M17
O204
M901 H2 P1
G04 P5
M17
O205
M901 H2 P0
G04 P5
M17
O208
M901 H24 P1
G04 P5
M17
O209
M901 H24 P0
G04 P5
M17
O686
#FC50=#FIXEDCYCLE_BACK
IF(!#FC13)G90 G65 P786
IF(#FC13)G91 G65 P786 L=#FC11
M17
O786
G00 X=#FC1 Y=#FC2
G90 G00 Z=#FC4
G90 G01 Z=#FC4-ABS(#FC5) F=#FC7
G65 P886 L=INT(ABS(#FC4-#FC3) /ABS (#FC5)) -1
G90 G01 Z=#FC3 F=#FC7
M05
G90 G00 Z=#FC4
IF(!#FC12)G90 G00 Z=#FC14
M03
IF(#FC13)G91
M17
O886
G91 G00 Z=#FC50
G91 G00 Z=-#FC50
G91 G01 Z=-ABS(#FC5) F=#FC7
M17
O"helper"
G1 X77
M17

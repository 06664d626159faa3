' S0 §3.5.3 floating tool-setting routine (public.dat lift program), after selecting tool 1
' with length compensation and raising Z to 20
T1
G43 G90 G00 Z20
M802 P196609
M801 MSG "|D|等待对刀信号"
G904 FZ-60 PZ=#CALIBRATION_SW LZ1
M801 MSG ""
M802 P196608
G903 G00 G91 Z5
G923 Z0
G906
G923 Z = #CURWORKPOS.Z - #MOBICALI_THICKNESS - 5
G90 G00 Z0
M30

’ S1 §3.5 examples of expressions in program words (EX-34)
G=1+2 X10 Y0 R5 F600
G00 X3 Y5 Z=5+sin(5+abs(-8))
#1=4+log6
G01 X2 Y=#1
#2=5
#3=8
#4=2
G00 X=#2 Y=#3 Z=#4
M30

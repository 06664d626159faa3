# Independent geometry for EX-06: compose 3x3 homogeneous matrices in programmed order.
import math, re, sys
def mul(a,b): return [[sum(a[i][k]*b[k][j] for k in range(3)) for j in range(3)] for i in range(3)]
def T(x,y): return [[1,0,x],[0,1,y],[0,0,1]]
def R(d):
    c,s=math.cos(math.radians(d)),math.sin(math.radians(d)); return [[c,-s,0],[s,c,0],[0,0,1]]
def S(f): return [[f,0,0],[0,f,0],[0,0,1]]
def about(c,m): return mul(mul(T(*c),m),T(-c[0],-c[1]))
M=[[1,0,0],[0,1,0],[0,0,1]]
rect=[(200,0),(200,-100),(0,-100),(0,0)]
exp=[]
def draw():
    for p in rect:
        v=[M[i][0]*p[0]+M[i][1]*p[1]+M[i][2] for i in range(2)]; exp.append(v)
draw()
for k in range(10):
    M=mul(M,about((50,50),R(45))); draw()
    M=mul(M,about((50,50),S(0.5))); draw()
got=[(float(a),float(b)) for a,b in re.findall(r'feed X(\S+) Y(\S+) Z', open(sys.argv[1]).read())]
assert len(got)==len(exp)==84, (len(got),len(exp))
worst=max(max(abs(g[0]-e[0]),abs(g[1]-e[1])) for g,e in zip(got,exp))
print("84 feed end points, worst deviation", worst); assert worst<6e-5

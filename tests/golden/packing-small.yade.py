# demcheck: a Yade packing script (Python), generated from a fixed template
# every value below is a number written by demcheck
# demcheck packing script for yade (written for Yade 2023.02a (yade -x -n))
# case: poured-small-poly (hash 8cbe08e57f10f0ce)
# model: normal = lsd, tangential = spring_sliding, limit_force = false; mapping fidelity: approximate
#   Yade's ViscElPhys holds the total normal force at \u2265 0 (it drops the dashpot's attraction at the end of the contact); the case has limit_force = false
#   oblique impacts: on a wall Yade's slip velocity and torque use the arm R \u2212 \u03b4 (the contact point on the wall's plane), and it turns the history with ScGeom's first-order rotation
#   Yade combines the species' materials in series: species 1 with 2 gets cn = 0.03722531661, the case's is 0.03706332383 (+0.437 %)
#   Yade combines the species' materials in series: species 1 with 3 gets cn = 0.04647773677, the case's is 0.04365450477 (+6.47 %)
#   Yade combines the species' materials in series: species 2 with 3 gets cn = 0.05262791026, the case's is 0.05065977831 (+3.88 %)
#   the floor is a fixed Box (Ig2_Box_Sphere_ScGeom): its slip and torque arm is R \u2212 \u03b4/2 (the contact point midway into the overlap), a Wall's R \u2212 \u03b4
# 30 particles of 3 species; 267713 steps of dt = 3.735347976579279e-07 s (0.1 s); final state: final.txt (every particle), contacts.txt (every particle pair in contact)
# run by hand: yade -x -n <this file> (it writes both files in the working directory and prints 'step ke atoms' lines)
from yade import utils

# the run: dt (s), steps, gravity (m/s^2), the steps whose translational kinetic energy is printed (every 5354 and the last)
DT = 3.735347976579279e-07
STEPS = 267713
G = Vector3(0.0, 0.0, -9.81)
SAMPLES = [0, 5354, 10708, 16062, 21416, 26770, 32124, 37478, 42832, 48186, 53540, 58894, 64248, 69602, 74956, 80310, 85664, 91018, 96372, 101726, 107080, 112434, 117788, 123142, 128496, 133850, 139204, 144558, 149912, 155266, 160620, 165974, 171328, 176682, 182036, 187390, 192744, 198098, 203452, 208806, 214160, 219514, 224868, 230222, 235576, 240930, 246284, 251638, 256992, 262346, 267700, 267713]
# Yade's periodic cell (periodic in x, y and z): x and y the case's box, z twice the height of the box and the floor, so nothing reaches across it
O.periodic = True
O.cell.setBox(0.011, 0.011, 0.024781901154727747)
LX = 0.011
LY = 0.011
# material k: species k + 1 (it carries twice its like pair's values: Yade combines two materials in series); after them the floor's (one per group of species, each group masked to its own floor)
# species 1: glass, radius 0.0006 m, mass 2.2619467105846507e-06 kg
O.materials.append(ViscElMat(kn=4000.0, cn=0.06807863683040408, ks=3294.1176470588234, cs=0.0, frictionAngle=0.4636476090008061, density=1.0))
# species 2: glass, radius 0.00068 m, mass 3.2927242041784867e-06 kg
O.materials.append(ViscElMat(kn=4000.0, cn=0.08213860912793433, ks=3294.1176470588234, cs=0.0, frictionAngle=0.4636476090008061, density=1.0))
# species 3: glass, radius 0.001 m, mass 1.0471975511965977e-05 kg
O.materials.append(ViscElMat(kn=4000.0, cn=0.14648190370925437, ks=3294.1176470588234, cs=0.0, frictionAngle=0.4636476090008061, density=1.0))
# the floor of species 1: the wall's values of the case in series with the species' material
O.materials.append(ViscElMat(kn=4000.0, cn=0.16435636834383394, ks=3294.1176470588234, cs=0.0, frictionAngle=0.4636476090008061, density=1.0))
# the floor of species 2: the wall's values of the case in series with the species' material
O.materials.append(ViscElMat(kn=4000.0, cn=0.19830014415112168, ks=3294.1176470588234, cs=0.0, frictionAngle=0.4636476090008061, density=1.0))
# the floor of species 3: the wall's values of the case in series with the species' material
O.materials.append(ViscElMat(kn=4000.0, cn=0.35363859857711194, ks=3294.1176470588234, cs=0.0, frictionAngle=0.4636476090008061, density=1.0))
# species 1 with 1: ViscElMat kn, cn given directly: the pair's kn = 2000 N/m, cn = 0.03403931842 kg/s (each material carries twice: Yade combines them in series); ViscElMat ks = 1647.058824 N/m, cs = 0 kg/s, frictionAngle = atan \u03bc
# species 1 with 2: ViscElMat kn, cn given directly: the pair's kn = 2000 N/m, cn = 0.03706332383 kg/s (each material carries twice: Yade combines them in series); ViscElMat ks = 1647.058824 N/m, cs = 0 kg/s, frictionAngle = atan \u03bc
# species 1 with 3: ViscElMat kn, cn given directly: the pair's kn = 2000 N/m, cn = 0.04365450477 kg/s (each material carries twice: Yade combines them in series); ViscElMat ks = 1647.058824 N/m, cs = 0 kg/s, frictionAngle = atan \u03bc
# species 2 with 2: ViscElMat kn, cn given directly: the pair's kn = 2000 N/m, cn = 0.04106930456 kg/s (each material carries twice: Yade combines them in series); ViscElMat ks = 1647.058824 N/m, cs = 0 kg/s, frictionAngle = atan \u03bc
# species 2 with 3: ViscElMat kn, cn given directly: the pair's kn = 2000 N/m, cn = 0.05065977831 kg/s (each material carries twice: Yade combines them in series); ViscElMat ks = 1647.058824 N/m, cs = 0 kg/s, frictionAngle = atan \u03bc
# species 3 with 3: ViscElMat kn, cn given directly: the pair's kn = 2000 N/m, cn = 0.07324095185 kg/s (each material carries twice: Yade combines them in series); ViscElMat ks = 1647.058824 N/m, cs = 0 kg/s, frictionAngle = atan \u03bc
# species 1 with the walls: ViscElMat kn, cn given directly: the pair's kn = 2000 N/m, cn = 0.04813886576 kg/s (each material carries twice: Yade combines them in series); ViscElMat ks = 1647.058824 N/m, cs = 0 kg/s, frictionAngle = atan \u03bc
# species 2 with the walls: ViscElMat kn, cn given directly: the pair's kn = 2000 N/m, cn = 0.05808076751 kg/s (each material carries twice: Yade combines them in series); ViscElMat ks = 1647.058824 N/m, cs = 0 kg/s, frictionAngle = atan \u03bc
# species 3 with the walls: ViscElMat kn, cn given directly: the pair's kn = 2000 N/m, cn = 0.1035783474 kg/s (each material carries twice: Yade combines them in series); ViscElMat ks = 1647.058824 N/m, cs = 0 kg/s, frictionAngle = atan \u03bc
# every particle: material (its species), radius (m), mass (kg), moment of inertia 0.4 m r^2 (kg m^2), position (m),
# velocity v0 - dt/2 g (leap-frog's v at -dt/2, so that v0 is the full-step velocity at step 0: no contact at t = 0), angular velocity (rad/s)
P = [
    (0, 0.0006, 2.2619467105846507e-06, 3.257203263241896e-13, 0.0010953131878219465, 0.0011973470919523672, 0.0012542294037371513, 0.0, 0.0, 1.8321881825121364e-06, 0.0, 0.0, 0.0),
    (1, 0.00068, 3.2927242041784867e-06, 6.09022268804853e-13, 0.004180459374343449, 0.0011010368335122693, 0.0011879628492425652, 0.0, 0.0, 1.8321881825121364e-06, 0.0, 0.0, 0.0),
    (2, 0.001, 1.0471975511965977e-05, 4.188790204786392e-12, 0.006860859626245062, 0.001145323767380028, 0.0012422238872536585, 0.0, 0.0, 1.8321881825121364e-06, 0.0, 0.0, 0.0),
    (0, 0.0006, 2.2619467105846507e-06, 3.257203263241896e-13, 0.009364228613446947, 0.0013015790285845717, 0.0012030132328718455, 0.0, 0.0, 1.8321881825121364e-06, 0.0, 0.0, 0.0),
    (1, 0.00068, 3.2927242041784867e-06, 6.09022268804853e-13, 0.00132817391377957, 0.0041835890357207455, 0.0012428108017125887, 0.0, 0.0, 1.8321881825121364e-06, 0.0, 0.0, 0.0),
    (2, 0.001, 1.0471975511965977e-05, 4.188790204786392e-12, 0.004432980397014366, 0.003979335785530435, 0.0012267384972743684, 0.0, 0.0, 1.8321881825121364e-06, 0.0, 0.0, 0.0),
    (0, 0.0006, 2.2619467105846507e-06, 3.257203263241896e-13, 0.007007445797752354, 0.003985086505583429, 0.0011102682150315904, 0.0, 0.0, 1.8321881825121364e-06, 0.0, 0.0, 0.0),
    (1, 0.00068, 3.2927242041784867e-06, 6.09022268804853e-13, 0.009944585685467328, 0.003988920825536391, 0.0011665174803661806, 0.0, 0.0, 1.8321881825121364e-06, 0.0, 0.0, 0.0),
    (2, 0.001, 1.0471975511965977e-05, 4.188790204786392e-12, 0.001639404972550481, 0.0069324849844263625, 0.0011948357397327295, 0.0, 0.0, 1.8321881825121364e-06, 0.0, 0.0, 0.0),
    (0, 0.0006, 2.2619467105846507e-06, 3.257203263241896e-13, 0.004309461981512951, 0.006557983555172168, 0.0012372537172180122, 0.0, 0.0, 1.8321881825121364e-06, 0.0, 0.0, 0.0),
    (1, 0.00068, 3.2927242041784867e-06, 6.09022268804853e-13, 0.006790114587597967, 0.006598825581615373, 0.001228890012137021, 0.0, 0.0, 1.8321881825121364e-06, 0.0, 0.0, 0.0),
    (2, 0.001, 1.0471975511965977e-05, 4.188790204786392e-12, 0.009916238101950414, 0.006677354038454675, 0.0012234162359613617, 0.0, 0.0, 1.8321881825121364e-06, 0.0, 0.0, 0.0),
    (0, 0.0006, 2.2619467105846507e-06, 3.257203263241896e-13, 0.0012387600861937615, 0.009788185759046797, 0.001239989665465581, 0.0, 0.0, 1.8321881825121364e-06, 0.0, 0.0, 0.0),
    (1, 0.00068, 3.2927242041784867e-06, 6.09022268804853e-13, 0.003935132911583943, 0.009847673640135161, 0.0012283773979571836, 0.0, 0.0, 1.8321881825121364e-06, 0.0, 0.0, 0.0),
    (2, 0.001, 1.0471975511965977e-05, 4.188790204786392e-12, 0.006998389262805735, 0.009841051131365111, 0.0011871431227737231, 0.0, 0.0, 1.8321881825121364e-06, 0.0, 0.0, 0.0),
    (0, 0.0006, 2.2619467105846507e-06, 3.257203263241896e-13, 0.00979962618627957, 0.009880474124649721, 0.0011284175859459732, 0.0, 0.0, 1.8321881825121364e-06, 0.0, 0.0, 0.0),
    (1, 0.00068, 3.2927242041784867e-06, 6.09022268804853e-13, 0.0016110936277896537, 0.0013034009495268262, 0.0033963431062322097, 0.0, 0.0, 1.8321881825121364e-06, 0.0, 0.0, 0.0),
    (2, 0.001, 1.0471975511965977e-05, 4.188790204786392e-12, 0.003886275834586784, 0.001508937782839288, 0.0033625561508778133, 0.0, 0.0, 1.8321881825121364e-06, 0.0, 0.0, 0.0),
    (0, 0.0006, 2.2619467105846507e-06, 3.257203263241896e-13, 0.007125518926110672, 0.001223377704439952, 0.0034111257493715606, 0.0, 0.0, 1.8321881825121364e-06, 0.0, 0.0, 0.0),
    (1, 0.00068, 3.2927242041784867e-06, 6.09022268804853e-13, 0.009557267949263055, 0.0014512139070341464, 0.0033453950631589825, 0.0, 0.0, 1.8321881825121364e-06, 0.0, 0.0, 0.0),
    (2, 0.001, 1.0471975511965977e-05, 4.188790204786392e-12, 0.0011591940900690892, 0.0042916307603136404, 0.00344540021530647, 0.0, 0.0, 1.8321881825121364e-06, 0.0, 0.0, 0.0),
    (0, 0.0006, 2.2619467105846507e-06, 3.257203263241896e-13, 0.004170210065255716, 0.004409228782165978, 0.0033470395086812234, 0.0, 0.0, 1.8321881825121364e-06, 0.0, 0.0, 0.0),
    (1, 0.00068, 3.2927242041784867e-06, 6.09022268804853e-13, 0.007111858259099364, 0.0039015664351457835, 0.0034835843897609705, 0.0, 0.0, 1.8321881825121364e-06, 0.0, 0.0, 0.0),
    (2, 0.001, 1.0471975511965977e-05, 4.188790204786392e-12, 0.009708492591471652, 0.00419714655690676, 0.0034847005773638727, 0.0, 0.0, 1.8321881825121364e-06, 0.0, 0.0, 0.0),
    (0, 0.0006, 2.2619467105846507e-06, 3.257203263241896e-13, 0.0015687470818074203, 0.007070694296359773, 0.003319736876416774, 0.0, 0.0, 1.8321881825121364e-06, 0.0, 0.0, 0.0),
    (1, 0.00068, 3.2927242041784867e-06, 6.09022268804853e-13, 0.004036768256613733, 0.00659480397121169, 0.003344834964663793, 0.0, 0.0, 1.8321881825121364e-06, 0.0, 0.0, 0.0),
    (2, 0.001, 1.0471975511965977e-05, 4.188790204786392e-12, 0.006681860218717198, 0.007117083304211984, 0.0033328158963492954, 0.0, 0.0, 1.8321881825121364e-06, 0.0, 0.0, 0.0),
    (0, 0.0006, 2.2619467105846507e-06, 3.257203263241896e-13, 0.009487811493662878, 0.006870171710773924, 0.003462902874014117, 0.0, 0.0, 1.8321881825121364e-06, 0.0, 0.0, 0.0),
    (1, 0.00068, 3.2927242041784867e-06, 6.09022268804853e-13, 0.0016890312090652284, 0.009765497720213888, 0.003348463699497499, 0.0, 0.0, 1.8321881825121364e-06, 0.0, 0.0, 0.0),
    (2, 0.001, 1.0471975511965977e-05, 4.188790204786392e-12, 0.004155363309984153, 0.009764022354016149, 0.003319338854990793, 0.0, 0.0, 1.8321881825121364e-06, 0.0, 0.0, 0.0),
]
# each species' mask: bit 0 (every particle touches every particle) and its floor group's bit
MASK = [3, 5, 9]
for p in P:
    b = O.bodies.append(utils.sphere(Vector3(p[4], p[5], p[6]), p[1], material=p[0], mask=MASK[p[0]]))
    O.bodies[b].state.mass = p[2]
    O.bodies[b].state.inertia = Vector3(p[3], p[3], p[3])
    O.bodies[b].state.vel = Vector3(p[7], p[8], p[9])
    O.bodies[b].state.angVel = Vector3(p[10], p[11], p[12])
N = len(P)
# wall 0: the plane z = 0, facing +z (a floor), a fixed Box whose face is the plane (a Wall hangs Yade's periodic collider)
b = O.bodies.append(utils.box(Vector3(0.0055, 0.0055, -0.001953125), Vector3(16.0, 16.0, 0.001953125), fixed=True, material=3, mask=2))
O.bodies[b].state.mass = 0.0
b = O.bodies.append(utils.box(Vector3(0.0055, 0.0055, -0.001953125), Vector3(16.0, 16.0, 0.001953125), fixed=True, material=4, mask=4))
O.bodies[b].state.mass = 0.0
b = O.bodies.append(utils.box(Vector3(0.0055, 0.0055, -0.001953125), Vector3(16.0, 16.0, 0.001953125), fixed=True, material=5, mask=8))
O.bodies[b].state.mass = 0.0
# the engines: Yade's leap-frog NewtonIntegrator without its numerical damping (0.2 in many examples)
O.engines = [ForceResetter(), InsertionSortCollider([Bo1_Sphere_Aabb(), Bo1_Box_Aabb()], allowBiggerThanPeriod=True, sortAxis=2),
              InteractionLoop([Ig2_Sphere_Sphere_ScGeom(), Ig2_Box_Sphere_ScGeom()], [Ip2_ViscElMat_ViscElMat_ViscElPhys()], [Law2_ScGeom_ViscElPhys_Basic()]),
              NewtonIntegrator(damping=0.0, gravity=G)]
O.dt = DT
# at each sample step s: the state x_s, v_{s-1/2}, w_{s-1/2}; one step computes F_s; the full-step velocity v_s = v_{s-1/2} + dt/2 (F_s/m + g)
done = 0
for s in SAMPLES:
    if s > done:
        O.run(s - done, True)
    x = [Vector3(O.bodies[i].state.pos) for i in range(N)]
    v = [Vector3(O.bodies[i].state.vel) for i in range(N)]
    w = [Vector3(O.bodies[i].state.angVel) for i in range(N)]
    O.step()
    e = 0.0
    for i in range(N):
        a = v[i] + (O.forces.f(i) / P[i][2] + G) * (0.5 * DT)
        e = e + 0.5 * P[i][2] * a.dot(a)
    print('%d %.17g %d' % (s, e, N))
    done = s + 1
# the final state at step STEPS: every particle (id = body id + 1, type = species; radius and mass as Yade holds them), F + m g as the LAMMPS-family engines write a particle's force; x and y wrapped into the box
out = open('final.txt', 'w')
out.write('ITEM: TIMESTEP\n%d\nITEM: NUMBER OF ATOMS\n%d\nITEM: BOX BOUNDS pp pp ff\n%.17g %.17g\n%.17g %.17g\n%.17g %.17g\nITEM: ATOMS id type radius mass x y z vx vy vz omegax omegay omegaz fx fy fz\n' % (STEPS, N, 0.0, 0.011, 0.0, 0.011, -0.001, 0.008484700577363873))
for i in range(N):
    f = O.forces.f(i)
    t = O.forces.t(i)
    a = v[i] + (f / P[i][2] + G) * (0.5 * DT)
    q = w[i] + t * (0.5 * DT / P[i][3])
    f = f + G * P[i][2]
    b = O.bodies[i]
    out.write('%d %d %.17g %.17g %.17g %.17g %.17g %.17g %.17g %.17g %.17g %.17g %.17g %.17g %.17g %.17g\n' % (i + 1, P[i][0] + 1, b.shape.radius, b.state.mass, x[i][0] - LX * (x[i][0] // LX), x[i][1] - LY * (x[i][1] // LY), x[i][2], a[0], a[1], a[2], q[0], q[1], q[2], f[0], f[1], f[2]))
out.close()
# every particle pair in contact at step STEPS (the floor's contacts left out): the ids, penetrationDepth, the normal force on the second (repulsive along the normal),
# the stored shear force (ViscElPhys: its elastic part; MindlinPhys: without the dashpot) and the normal from the first to the second
rows = [c for c in O.interactions if c.isReal and c.id1 < N and c.id2 < N]
out = open('contacts.txt', 'w')
out.write('ITEM: TIMESTEP\n%d\nITEM: NUMBER OF ENTRIES\n%d\nITEM: BOX BOUNDS pp pp ff\n%.17g %.17g\n%.17g %.17g\n%.17g %.17g\nITEM: ENTRIES id1 id2 overlap fnx fny fnz fsx fsy fsz nx ny nz\n' % (STEPS, len(rows), 0.0, 0.011, 0.0, 0.011, -0.001, 0.008484700577363873))
for c in rows:
    f = c.phys.normalForce
    t = c.phys.shearForce
    a = c.geom.normal
    out.write('%d %d %.17g %.17g %.17g %.17g %.17g %.17g %.17g %.17g %.17g %.17g\n' % (c.id1 + 1, c.id2 + 1, c.geom.penetrationDepth, f[0], f[1], f[2], t[0], t[1], t[2], a[0], a[1], a[2]))
out.close()

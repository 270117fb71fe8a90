#!/usr/bin/env python3
"""Each well-matched keyframe pair of a venue map folder against its own two-view geometry.

    python3 scripts/two-view-pairs.py <map-dir> <groundtruth.txt> [min-inliers (300)]

For every pair COLMAP verified with an essential matrix (config 2 or 6) and min-inliers matches
between two registered frames: its configuration, inliers, the angle between the rotation its
essential matrix admits and the map's relative rotation (as mapping/map_check.cpp measures it)
and the ground truth's, the true rotation and baseline, and the median Sampson distance (pixels)
of its verified matches under the essential matrix, the map's poses, the truth's poses, and the
map's poses with keyframe b turned 4 degrees about its optical axis (docs/mapping.md, "Pairs the
map's poses fit"). The map folder is a venue's (`arview map <room> <room> ...`: image names
<room>/frames/..., the rooms' frames.txt under <map-dir>/rooms/); keyframes.txt and the ground
truth are TUM files with the frames' timestamps. Plain Python (no numpy): a 3x3 SVD by Jacobi.
"""
import array, math, os, sqlite3, struct, sys
mapdir, gtfile = sys.argv[1], sys.argv[2]
min_inl = int(sys.argv[3]) if len(sys.argv) > 3 else 300
def qmat(qx,qy,qz,qw):
    n=math.sqrt(qx*qx+qy*qy+qz*qz+qw*qw); qx,qy,qz,qw=qx/n,qy/n,qz/n,qw/n
    return [[1-2*(qy*qy+qz*qz),2*(qx*qy-qz*qw),2*(qx*qz+qy*qw)],[2*(qx*qy+qz*qw),1-2*(qx*qx+qz*qz),2*(qy*qz-qx*qw)],[2*(qx*qz-qy*qw),2*(qy*qz+qx*qw),1-2*(qx*qx+qy*qy)]]
def T(a): return [[a[j][i] for j in range(3)] for i in range(3)]
def mul(a,b): return [[sum(a[i][k]*b[k][j] for k in range(3)) for j in range(3)] for i in range(3)]
def ang(r): return math.degrees(math.acos(max(-1,min(1,(r[0][0]+r[1][1]+r[2][2]-1)/2))))
def det(m): return (m[0][0]*(m[1][1]*m[2][2]-m[1][2]*m[2][1])-m[0][1]*(m[1][0]*m[2][2]-m[1][2]*m[2][0])+m[0][2]*(m[1][0]*m[2][1]-m[1][1]*m[2][0]))
def jacobi_eig(a):
    a=[row[:] for row in a]; v=[[float(i==j) for j in range(3)] for i in range(3)]
    for _ in range(100):
        off=max(abs(a[0][1]),abs(a[0][2]),abs(a[1][2]))
        if off<1e-15: break
        for p,q in ((0,1),(0,2),(1,2)):
            if abs(a[p][q])<1e-300: continue
            th=(a[q][q]-a[p][p])/(2*a[p][q]); t=(1 if th>=0 else -1)/(abs(th)+math.sqrt(th*th+1)); c=1/math.sqrt(t*t+1); s=t*c
            for k in range(3):
                akp,akq=a[k][p],a[k][q]; a[k][p]=c*akp-s*akq; a[k][q]=s*akp+c*akq
            for k in range(3):
                apk,aqk=a[p][k],a[q][k]; a[p][k]=c*apk-s*aqk; a[q][k]=s*apk+c*aqk
            for k in range(3):
                vkp,vkq=v[k][p],v[k][q]; v[k][p]=c*vkp-s*vkq; v[k][q]=s*vkp+c*vkq
    return [a[i][i] for i in range(3)], v
def svd(m):
    w,v=jacobi_eig(mul(T(m),m)); order=sorted(range(3),key=lambda i:-w[i])
    V=[[v[r][i] for i in order] for r in range(3)]; s=[math.sqrt(max(w[i],0)) for i in order]
    U=[[0]*3 for _ in range(3)]
    mv=mul(m,V)
    for i in range(2):
        for r in range(3): U[r][i]=mv[r][i]/s[i]
    c=[U[1][0]*U[2][1]-U[2][0]*U[1][1],U[2][0]*U[0][1]-U[0][0]*U[2][1],U[0][0]*U[1][1]-U[1][0]*U[0][1]]
    for r in range(3): U[r][2]=c[r]
    return U,s,V
def e_rots(E):
    U,s,V=svd(E)
    if det(U)<0: U=[[-x for x in r] for r in U]
    if det(V)<0: V=[[-x for x in r] for r in V]
    W=[[0,-1,0],[1,0,0],[0,0,1]]
    return [mul(mul(U,W),T(V)), mul(mul(U,T(W)),T(V))], s
def off(E,R):
    rs,s=e_rots(E); return min(ang(mul(T(c),R)) for c in rs)
def read_tum(f):
    d={}
    for l in open(f):
        if l.startswith('#') or not l.strip(): continue
        x=list(map(float,l.split())); d[round(x[0],4)]=(x[1:4],qmat(*x[4:8]))
    return d
gt=read_tum(gtfile); kf=read_tum(os.path.join(mapdir,'keyframes.txt'))
names=[l.strip() for l in open(os.path.join(mapdir,'image_list.txt'))]
# timestamps of each name from the rooms' frames.txt
ts={}
for n in names:
    room=n.split('/')[0]
    if room not in ts:
        ts[room]={}
        for l in open(os.path.join(mapdir,'rooms',room,'frames.txt')):
            if l.startswith('#'): continue
            t,p=l.split(); ts[room][p]=round(float(t),4)
def stamp(n): room,rest=n.split('/',1); return ts[room][rest]
db=sqlite3.connect('file:'+os.path.join(mapdir,'database.db')+'?mode=ro',uri=True)
img={i:n for i,n in db.execute('select image_id,name from images')}
frame={n:k for k,n in enumerate(names)}
# Sampson distance (pixels) of each compared pair's inliers under the map's pose, the truth's and COLMAP's E
cam=db.execute('select model,width,height,params from cameras').fetchone()
par=struct.unpack('%dd'%(len(cam[3])//8),cam[3]); f,cx,cy=(par[0],par[1],par[2]) if cam[0] in (0,2) else (par[0],par[2],par[3])
kp={}
for iid,r,c,d in db.execute('select image_id,rows,cols,data from keypoints'):
    a=array.array('f'); a.frombytes(d); kp[iid]=[((a[c*k]-cx)/f,(a[c*k+1]-cy)/f) for k in range(r)]
def skew(t): return [[0,-t[2],t[1]],[t[2],0,-t[0]],[-t[1],t[0],0]]
def sampson(E,pa,pb):
    out=[]
    for (x1,y1),(x2,y2) in zip(pa,pb):
        Ex1=[E[i][0]*x1+E[i][1]*y1+E[i][2] for i in range(3)]
        Etx2=[E[0][i]*x2+E[1][i]*y2+E[2][i] for i in range(3)]
        e=x2*Ex1[0]+y2*Ex1[1]+Ex1[2]
        out.append(abs(e)/math.sqrt(Ex1[0]**2+Ex1[1]**2+Etx2[0]**2+Etx2[1]**2)*f)
    out.sort(); return out[len(out)//2]
def pose_E(pa,pb):  # world-to-camera R, centre c of a and b -> E_ab
    Ra,ca=T(pa[1]),pa[0]; Rb,cb=T(pb[1]),pb[0]
    R=mul(Rb,T(Ra)); d=[cb[i]-ca[i] for i in range(3)]; t=[-sum(Rb[i][k]*d[k] for k in range(3)) for i in range(3)]
    return mul(skew(t),R)
def rotz(deg):
    c,s=math.cos(math.radians(deg)),math.sin(math.radians(deg)); return [[c,-s,0],[s,c,0],[0,0,1]]
print('frame_a frame_b config inliers off_map_deg off_truth_deg true_rot_deg true_baseline px_E px_map px_truth px_map_turned')
for pid,nin,cfg,E,data in db.execute('select pair_id,rows,config,E,data from two_view_geometries where rows>=?',(min_inl,)):
    i2=pid%2147483647; i1=(pid-i2)//2147483647
    if cfg not in (2,6) or E is None: continue
    a,b=img[i1],img[i2]; ta,tb=stamp(a),stamp(b)
    if ta not in kf or tb not in kf: continue
    m=array.array('I'); m.frombytes(data)
    pa=[kp[i1][m[2*k]] for k in range(nin)]; pb=[kp[i2][m[2*k+1]] for k in range(nin)]
    Em=[list(struct.unpack('9d',E)[3*r:3*r+3]) for r in range(3)]
    rt=lambda p: T(p[1])  # world-to-camera rotation
    Rg=mul(rt(gt[tb]),T(rt(gt[ta])))
    om=off(Em,mul(rt(kf[tb]),T(rt(kf[ta]))))
    turned=(kf[tb][0], mul(kf[tb][1], rotz(4)))
    print('%3d %3d %d %5d %6.2f %6.2f %6.1f %6.3f %6.3f %6.3f %6.3f %6.3f'%(frame[a],frame[b],cfg,nin,om,off(Em,Rg),ang(Rg),math.dist(gt[ta][0],gt[tb][0]),
          sampson(Em,pa,pb),sampson(pose_E(kf[ta],kf[tb]),pa,pb),sampson(pose_E(gt[ta],gt[tb]),pa,pb),sampson(pose_E(kf[ta],turned),pa,pb)))

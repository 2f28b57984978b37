# Prototype of methods/group/eps_cayley.hpp in NumPy (the helper's check before the C++ was built;
# its numbers are quoted in the eps commit messages).  check: D1, D2 of L_d against finite differences.
import numpy as np
def hat(x): return np.array([[0,-x[2],x[1]],[x[2],0,-x[0]],[-x[1],x[0],0]])
def vee(X): return np.array([X[2,1],X[0,2],X[1,0]])
def cay(y): return np.linalg.solve(np.eye(3)-hat(y)/2, np.eye(3)+hat(y)/2)
def caylog(W): # inverse: y with cay(y)=W: y^ = 2 (W - I)(W + I)^-1
    return vee(2*(W-np.eye(3))@np.linalg.inv(W+np.eye(3)))
def expm(x):
    from scipy.linalg import expm as E; return E(hat(x))
J=np.diag([1.,10.,100.]); h=0.3
rng=np.random.default_rng(1)
R0=expm(rng.normal(size=3)); y=rng.normal(size=3)*0.5; R1=R0@cay(y)
def Ld(R0,R1):
    x=caylog(R0.T@R1)/h; return h*0.5*x@J@x
mu=J@y/h
eps=1e-6
D1=np.array([(Ld(R0@expm(eps*e),R1)-Ld(R0@expm(-eps*e),R1))/(2*eps) for e in np.eye(3)])
D2=np.array([(Ld(R0,R1@expm(eps*e))-Ld(R0,R1@expm(-eps*e)))/(2*eps) for e in np.eye(3)])
dinv=lambda x: np.eye(3)-hat(x)/2+np.outer(x,x)/4
print(D1, -(dinv(y).T@mu))
print(D2, dinv(-y).T@mu)

# ---- the scheme on suslov_fz: order against solve_ivp, the decay rate after the turnover
import numpy as np
from scipy.integrate import solve_ivp
def hat(x): return np.array([[0,-x[2],x[1]],[x[2],0,-x[0]],[-x[1],x[0],0]])
def G(p,u):
    w,x,y,z=p
    return np.array([[-x,w,z,-y],[-y,-z,w,x],[-z,y,-x,w]])@u
Jd=np.array([1.,10.,100.]); J=np.diag(Jd)
def step(M,a,h,y0):
    # solve (I + y^/2 + yy^T/4) J y/h = M + lam a, <a,y>=0
    y=y0.copy(); lam=0.0
    for it in range(50):
        Jy=J@y
        f=(Jy+0.5*np.cross(y,Jy)+0.25*y*(y@Jy))/h - M - lam*a
        g=a@y/h
        Jf=(J+0.5*(hat(y)@J-hat(Jy))+0.25*(np.outer(y,2*Jy)+(y@Jy)*np.eye(3)))/h
        K=np.zeros((4,4)); K[:3,:3]=Jf; K[:3,3]=-a; K[3,:3]=a/h
        d=np.linalg.solve(K,-np.concatenate([f,[g]]))
        y+=d[:3]; lam+=d[3]
        if np.abs(d).max()<1e-15*(1+np.abs(y).max()): break
    Jy=J@y
    Mn=(Jy-0.5*np.cross(y,Jy)+0.25*y*(y@Jy))/h
    return y,lam,Mn
def proj(M,a):
    Om=M/Jd; Ia=a/Jd
    return Om - (a@Om)/(a@Ia)*Ia
def run(Om0,a,h,N):
    M=J@Om0; y=h*Om0; Oms=[Om0]; ys=[]
    for k in range(N):
        y,lam,M=step(M,a,h,y); Oms.append(proj(M,a)); ys.append(y)
    return np.array(Oms),np.array(ys)
def exact(Om0,a,T,t_eval=None):
    Ia=a/Jd
    def f(t,Om):
        c=np.cross(J@Om,Om)/Jd
        return c-(a@c)/(a@Ia)*Ia
    return solve_ivp(f,(0,T),Om0,rtol=1e-13,atol=1e-14,method='DOP853',t_eval=t_eval)
p0=np.array([0.9,0.3,0.3,0.1]); v0=np.array([0.14991,-0.45013,-0.04955,0.14985])
a=np.array([0,0.6,0.8])
Om0=2*G(p0,v0); print("Om0",Om0, a@Om0)
Om0=Om0-(a@Om0)/(a@a)*a
T=4.0
ref=exact(Om0,a,T).y[:,-1]
for h in [0.1,0.05,0.025,0.0125]:
    Oms,ys=run(Om0,a,h,int(round(T/h)))
    print(h, np.abs(Oms[-1]-ref).max())
# asymptotics
b=np.array([0,0.8,-0.6])
E0=0.5*Om0@J@Om0; c=np.sqrt(2*E0/Jd[0]); k=0.48*(100-10); Jb=b@J@b; kap=k*c/Jb
print("c",c,"kappa",kap)
T=40
for h in [0.2,0.1,0.05,0.02]:
    N=int(round(T/h)); Oms,ys=run(Om0,a,h,N)
    u=Oms[:,0]; w=Oms@b; t=np.arange(N+1)*h
    E=0.5*np.einsum('ki,i,ki->k',Oms,Jd,Oms)
    # rate in window where |w| between 1e-3 and 1e-8 after turnover
    sel=(t>8)&(np.abs(w)<1e-3)&(np.abs(w)>1e-10)
    rate=-np.polyfit(t[sel],np.log(np.abs(w[sel])),1)[0] if sel.sum()>3 else float('nan')
    print(h,"u_end",u[-1],"w_end",w[-1],"rate",rate,"E drift",E[-1]-E0, "maxdE",np.abs(E-E0).max())

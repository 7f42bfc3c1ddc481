C     Reference runs of Hairer and Wanner's radau5.f for eomgen's RADAU5 test
C     (runtime/tests/radau5_reference.rs). Each case prints the statistics
C     radau5.f keeps in IWORK(14..20) and the final state.
C
C     Build and run with run.sh in this directory.
      PROGRAM PROBLEMS
      IMPLICIT DOUBLE PRECISION (A-H,O-Z)
      CALL CASE(1, 1.0D-6, 2.0D0, -0.66D0, 0.0D0, 2.0D0, 1.0D-4,
     &          1.0D-4)
      CALL CASE(2, 1.0D-6, 2.0D0, -0.66D0, 0.0D0, 2.0D0, 1.0D-7,
     &          1.0D-7)
      CALL CASE(3, 1.0D-6, 2.0D0, -0.66D0, 0.0D0, 2.0D0, 1.0D-2,
     &          1.0D-2)
      CALL CASE(4, 0.0D0, 1.0D0, 0.0D0, 0.0D0, 1.0D5, 1.0D-6,
     &          1.0D-10)
      END
C
C     Problem 1-3: van der Pol, y1' = y2, y2' = ((1 - y1^2) y2 - y1)/EPS.
C     Problem 4: Robertson's reaction, y = (1, 0, 0) at t = 0.
      SUBROUTINE CASE(K, EPS, Y10, Y20, X0, XEND0, RTOL0, ATOL0)
      IMPLICIT DOUBLE PRECISION (A-H,O-Z)
      PARAMETER (ND=3,LWORK=4*ND*ND+12*ND+20,LIWORK=3*ND+20)
      DIMENSION Y(ND),WORK(LWORK),IWORK(LIWORK),RPAR(2)
      INTEGER IPAR(1)
      EXTERNAL FCN,JAC,SOLOUT
      IPAR(1)=K
      RPAR(1)=EPS
      IF (K.LE.3) THEN
         N=2
         Y(1)=Y10
         Y(2)=Y20
      ELSE
         N=3
         Y(1)=1.0D0
         Y(2)=0.0D0
         Y(3)=0.0D0
      END IF
      X=X0
      XEND=XEND0
      RTOL=RTOL0
      ATOL=ATOL0
      H=1.0D-6
      DO I=1,20
         IWORK(I)=0
         WORK(I)=0.0D0
      END DO
C     Exact Jacobian, full; no mass matrix; no output routine. RADAU5
C     overwrites some of these, so they are variables.
      ITOL=0
      IJAC=1
      MLJAC=N
      MUJAC=0
      IMAS=0
      MLMAS=N
      MUMAS=0
      IOUT=0
      CALL RADAU5(N,FCN,X,Y,XEND,H,RTOL,ATOL,ITOL,JAC,IJAC,MLJAC,
     &            MUJAC,FCN,IMAS,MLMAS,MUMAS,SOLOUT,IOUT,WORK,LWORK,
     &            IWORK,LIWORK,RPAR,IPAR,IDID)
      WRITE(6,'(A,I2,A,I3,A,7I7)') 'case',K,' idid',IDID,
     &   ' nfcn njac nstep naccpt nrejct ndec nsol',
     &   (IWORK(I),I=14,20)
      WRITE(6,'(A,3ES25.16)') '  y =',(Y(I),I=1,N)
      END
C
      SUBROUTINE FCN(N,X,Y,F,RPAR,IPAR)
      IMPLICIT DOUBLE PRECISION (A-H,O-Z)
      DIMENSION Y(N),F(N),RPAR(*)
      INTEGER IPAR(*)
      IF (IPAR(1).LE.3) THEN
         F(1)=Y(2)
         F(2)=((1-Y(1)**2)*Y(2)-Y(1))/RPAR(1)
      ELSE
         F(1)=-0.04D0*Y(1)+1.0D4*Y(2)*Y(3)
         F(3)=3.0D7*Y(2)*Y(2)
         F(2)=0.04D0*Y(1)-1.0D4*Y(2)*Y(3)-F(3)
      END IF
      END
C
      SUBROUTINE JAC(N,X,Y,DFY,LDFY,RPAR,IPAR)
      IMPLICIT DOUBLE PRECISION (A-H,O-Z)
      DIMENSION Y(N),DFY(LDFY,N),RPAR(*)
      INTEGER IPAR(*)
      IF (IPAR(1).LE.3) THEN
         DFY(1,1)=0.0D0
         DFY(1,2)=1.0D0
         DFY(2,1)=(-2.0D0*Y(1)*Y(2)-1.0D0)/RPAR(1)
         DFY(2,2)=(1.0D0-Y(1)**2)/RPAR(1)
      ELSE
         DFY(1,1)=-0.04D0
         DFY(1,2)=1.0D4*Y(3)
         DFY(1,3)=1.0D4*Y(2)
         DFY(2,1)=0.04D0
         DFY(2,2)=-1.0D4*Y(3)-6.0D7*Y(2)
         DFY(2,3)=-1.0D4*Y(2)
         DFY(3,1)=0.0D0
         DFY(3,2)=6.0D7*Y(2)
         DFY(3,3)=0.0D0
      END IF
      END
C
      SUBROUTINE SOLOUT(NR,XOLD,X,Y,CONT,LRC,N,RPAR,IPAR,IRTRN)
      IMPLICIT DOUBLE PRECISION (A-H,O-Z)
      END

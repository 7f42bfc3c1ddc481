! Reference runs of Brent's procedure `zero` for eomgen's event-location test
! (runtime/tests/events.rs, `brent_takes_the_steps_of_brents_zero`).
!
! For each test function g on [0, 1] (g(0) < 0 < g(1)) and each start
! t0 = 0 and t0 = 1 it calls zero(t0, t0 + 1, machep = epsilon(1d0),
! t = tiny(1d0), t -> g(t - t0)) and prints t0 and, for the evaluations after
! the two at the ends, their number, the sum of the points in the order
! evaluated, and the last point. For t in [1, 2], t - 1 is exact. Build and
! run with run.sh.
module cases
  implicit none
  integer, parameter :: dp = kind(1.0d0)
  integer :: which
  real(dp) :: r, a, s, start
  integer :: evaluations
  real(dp) :: total, last
contains
  ! The same arithmetic, operation by operation, as `brent_case` in the test.
  real(dp) function g(t)
    real(dp), intent(in) :: t
    real(dp) :: x, t2, t4, t16
    select case (which)
    case (1)
      g = t * t * t - 0.1d0
    case (2)
      g = t * t - 1.0d-4
    case (3)
      x = t - 0.31d0
      g = (t - 0.3d0) * (1.0d0 + 1.0d6 * (x * x))
    case (4)
      if (t < 0.3d0) then
        g = -1.0d0
      else
        g = 1.0d0 + t
      end if
    case (5)
      x = t - 0.3d0
      g = sign(sqrt(abs(x)), x)
    case (6)
      x = t - 0.3d0
      g = x * x * x * x * x * x * x * x * x
    case (7)
      g = t - 1.0d-310
    case (8)
      g = 50.0d0 - 1.0d0 / (t + 0.01d0)
    case (9)
      t2 = t * t
      t4 = t2 * t2
      t16 = (t4 * t4) * (t4 * t4)
      g = t16 * t4 - 0.5d0
    case (10)
      ! Its value at 0.6, the secant point from (0, -1.5) and (1, 1), puts the
      ! next (inverse quadratic) point 0.45 from 0.6, a few rounding units
      ! short of three quarters of the bracket [0, 0.6]: rejected by the test
      ! 2p < 3mq - |tol q|, accepted without the - |tol q|.
      if (t == 0.0d0) then
        g = -1.5d0
      else if (t == 1.0d0) then
        g = 1.0d0
      else if (t == 0.6d0) then
        g = 0.6131299792238182d0
      else
        g = t - 0.1d0
      end if
    case default
      x = t - r
      select case (mod(which, 4))
      case (0)
        g = x * (0.01d0 + a * ((t - s) * (t - s)))
      case (1)
        g = sign(sqrt(abs(x)), x) * (1.0d0 + a * t)
      case (2)
        g = x * x * x + (1.0d-3 * a) * x
      case default
        g = x / (0.01d0 + (t - s) * (t - s))
      end select
    end select
  end function g

  real(dp) function counted(t)
    real(dp), intent(in) :: t
    evaluations = evaluations + 1
    if (evaluations > 2) then
      total = total + t
      last = t
    end if
    counted = g(t - start)
  end function counted

  ! frac(k c), as `f64::fract` computes it.
  real(dp) function frac(k, c)
    integer, intent(in) :: k
    real(dp), intent(in) :: c
    real(dp) :: x
    x = dble(k) * c
    frac = x - aint(x)
  end function frac
end module cases

program problems
  use cases
  implicit none
  real(dp), external :: zero
  real(dp) :: root
  integer :: k, j
  do j = 0, 1
  start = dble(j)
  do k = 1, 410
    which = k
    r = 0.02d0 + 0.96d0 * frac(k, 0.6180339887498949d0)
    a = 50.0d0 * frac(k, 0.7548776662466927d0)
    s = frac(k, 0.5698402909980532d0)
    evaluations = 0
    total = 0.0d0
    last = 0.0d0
    root = zero(start, start + 1.0d0, epsilon(1.0d0), tiny(1.0d0), counted)
    write (*, '(I4, F4.1, I5, 2ES27.17E3)') k, start, evaluations - 2, total, last
  end do
  end do
end program problems

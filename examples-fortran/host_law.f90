! A host code's own force law from Fortran: the same model and output as examples-c/host_law.c
! (NLvib's example 02 with the coupling cubic spring given as a bind(C) callback).
module host_cubic
  use, intrinsic :: iso_c_binding
  implicit none
contains
  ! F = k3 w^3 on w = q2 - q1, dF/dw = 3 k3 w^2; user_data points to k3. Called from the
  ! solver's threads: it only reads its arguments.
  integer(c_int32_t) function cubic_law(user_data, dim, w, force, jacobian) bind(C)
    type(c_ptr), value :: user_data
    integer(c_size_t), value :: dim
    real(c_double), intent(in) :: w(dim)
    real(c_double), intent(out) :: force(dim), jacobian(dim, dim)
    real(c_double), pointer :: k3
    cubic_law = 1
    if (dim /= 1) return
    call c_f_pointer(user_data, k3)
    force(1) = k3 * w(1)**3
    jacobian(1, 1) = 3 * k3 * w(1)**2
    cubic_law = 0
  end function
end module

program host_law
  use, intrinsic :: iso_c_binding
  use jprom
  use host_cubic
  implicit none
  real(c_double), target :: k3 = 0.0042d0
  real(c_double) :: omega, amps(2), a, b, before, after, worst, residual
  type(c_ptr) :: built_in, host, sweep, guess, sol
  type(c_funptr) :: law
  type(jprom_hbm_options) :: opts
  type(jprom_sweep_options) :: sweep_opts
  character(len=512) :: msg
  integer :: i, npts, s, reason, it, iterations, folds

  built_in = nlvib_two_dof()
  host = nlvib_two_dof()
  if (jp_add_polynomial_spring(built_in, 2, [0.0d0, 0.0d0, 0.0042d0], dof_b=1, message=msg) /= JPROM_OK) &
    call fail('polynomial coupling')
  law = c_funloc(cubic_law)
  if (jp_add_element_callback(host, 1, [2], law, c_loc(k3), dofs_b=[1], message=msg) /= JPROM_OK) &
    call fail('host-law coupling')

  call jp_default_options(opts, sweep_opts)
  opts%harmonics = 7
  opts%nt = 256
  sweep_opts%omega_start = 0.8d0
  sweep_opts%omega_end = 1.4d0
  if (jp_sweep(built_in, opts, sweep_opts, sweep, msg) /= JPROM_OK) call fail('jp_sweep')
  s = jp_sweep_n_points(sweep, npts)
  s = jp_sweep_end(sweep, reason, msg)
  write (*, '(a,i0,a,a)') '# NLvib example 02, H = 7: ', npts, ' points, ', trim(jp_sweep_end_name(reason))
  write (*, '(a)') '# index omega X1_q1_built_in X1_q1_host_law'
  ! each point's frequency solved with the host law from the built-in sweep's previous point
  worst = 0; iterations = 0; folds = 0
  do i = 1, npts
    guess = c_null_ptr
    if (i > 1) then
      if (jp_sweep_solution(sweep, i - 1, guess, msg) /= JPROM_OK) call fail('jp_sweep_solution')
    end if
    if (jp_sweep_point(sweep, i, omega, amps) /= JPROM_OK) call fail('jp_sweep_point')
    a = amps(1)
    if (jp_solve_point_from(host, omega, opts, guess, sol, msg) /= JPROM_OK) call fail('jp_solve_point_from')
    if (jp_solution_amplitude(sol, 1, 1, b) /= JPROM_OK) call fail('jp_solution_amplitude')
    if (jp_solution_convergence(sol, it, residual) /= JPROM_OK) call fail('jp_solution_convergence')
    if (abs(a - b) > 1d-8 * abs(a)) then
      ! near a fold the frequency has several solutions and Newton from the previous point may
      ! land on another one: solve again from the point itself
      s = jp_solution_free(sol)
      s = jp_solution_free(guess)
      if (jp_sweep_solution(sweep, i, guess, msg) /= JPROM_OK) call fail('jp_sweep_solution')
      if (jp_solve_point_from(host, omega, opts, guess, sol, msg) /= JPROM_OK) call fail('jp_solve_point_from')
      if (jp_solution_amplitude(sol, 1, 1, b) /= JPROM_OK) call fail('jp_solution_amplitude')
      if (jp_solution_convergence(sol, it, residual) /= JPROM_OK) call fail('jp_solution_convergence')
    end if
    write (*, '(i0,3(1x,es17.10e2))') i - 1, omega, a, b
    iterations = iterations + it
    ! folds (the sweep turns back in frequency) are not compared: two solutions meet there
    before = 0; after = 0
    if (i > 1 .and. i < npts) then
      s = jp_sweep_point(sweep, i - 1, before, amps)
      s = jp_sweep_point(sweep, i + 1, after, amps)
    end if
    if ((omega - before) * (after - omega) < 0) then
      folds = folds + 1
    else
      worst = max(worst, abs(a - b) / abs(a))
    end if
    s = jp_solution_free(sol)
    s = jp_solution_free(guess)
  end do
  write (*, '(a,i0,a)') '# host-law solves: ', iterations, ' Newton iterations in all'
  write (*, '(a,es9.2e2,a,i0,a)') '# host law vs built-in spring: largest relative difference of |X1| ', worst, &
    ' (', folds, ' fold points not compared)'
  s = jp_sweep_free(sweep)
  s = jp_model_free(built_in)
  s = jp_model_free(host)
  if (worst > 1.0d-8 .or. reason /= JPROM_SWEEP_REACHED_END) error stop 1

contains
  ! NLvib's chain: masses 1 and 0.05, springs 1 and 0.0453, dampers 0.002 and 0.013, force 0.11
  ! cos(W t) on q1, cubic spring 1 from q1 to ground.
  type(c_ptr) function nlvib_two_dof() result(model)
    real(c_double) :: m(2, 2), k(2, 2), c(2, 2)
    m = reshape([1.0d0, 0.0d0, 0.0d0, 0.05d0], [2, 2])
    k = reshape([1.0453d0, -0.0453d0, -0.0453d0, 0.0453d0], [2, 2])
    c = reshape([0.015d0, -0.013d0, -0.013d0, 0.013d0], [2, 2])
    if (jp_model_new(m, k, model, msg) /= JPROM_OK) call fail('jp_model_new')
    if (jp_set_damping_matrix(model, c, msg) /= JPROM_OK) call fail('jp_set_damping_matrix')
    if (jp_set_first_harmonic_force(model, [0.11d0, 0.0d0], [0.0d0, 0.0d0], msg) /= JPROM_OK) call fail('force')
    if (jp_set_outputs(model, [1, 2], msg) /= JPROM_OK) call fail('jp_set_outputs')
    if (jp_add_polynomial_spring(model, 1, [0.0d0, 0.0d0, 1.0d0], message=msg) /= JPROM_OK) call fail('cubic to ground')
  end function

  subroutine fail(what)
    character(len=*), intent(in) :: what
    write (*, '(a,a,a)') what, ' failed: ', trim(msg)
    error stop 1
  end subroutine
end program

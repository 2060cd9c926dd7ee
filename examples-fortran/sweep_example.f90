! jprom from Fortran: the same model and sweep as examples-c/sweep_example.c, same output.
program sweep_example
  use, intrinsic :: iso_c_binding
  use jprom
  implicit none
  integer, parameter :: n = 6
  real(c_double) :: mass(n, n), stiffness(n, n), frame(3, 3), fc(n), fs(n), omega, amps(2), coeffs(2, 7)
  type(c_ptr) :: model, sweep
  type(jprom_hbm_options) :: opts
  type(jprom_sweep_options) :: sweep_opts
  character(len=512) :: msg
  integer :: d, i, npts, s

  mass = 0; stiffness = 0
  do d = 1, 3
    mass(d, d) = 1; mass(3 + d, 3 + d) = 1
    stiffness(d, d) = 2.0d4; stiffness(3 + d, 3 + d) = 1.0d4
    stiffness(d, 3 + d) = -1.0d4; stiffness(3 + d, d) = -1.0d4
  end do
  frame = 0; frame(1, 1) = 1; frame(2, 2) = 1; frame(3, 3) = 1
  fc = 0; fc(1) = 5; fs = 0

  if (jp_model_new(mass, stiffness, model, msg) /= JPROM_OK) call fail('jp_model_new')
  if (jp_add_ground_contact(model, [4, 5, 6], frame, 3.0d4, 3.0d4, 5.0d4, 0.5d0, 20.0d0, msg) /= JPROM_OK) &
    call fail('jp_add_ground_contact')
  if (jp_set_damping(model, 0.0d0, 1.0d-4, msg) /= JPROM_OK) call fail('jp_set_damping')
  if (jp_set_first_harmonic_force(model, fc, fs, msg) /= JPROM_OK) call fail('jp_set_first_harmonic_force')
  if (jp_set_outputs(model, [1, 4], msg) /= JPROM_OK) call fail('jp_set_outputs')

  call jp_default_options(opts, sweep_opts)
  opts%harmonics = 3
  sweep_opts%omega_start = 60.0d0
  sweep_opts%omega_end = 160.0d0
  if (jp_sweep(model, opts, sweep_opts, sweep, msg) /= JPROM_OK) call fail('jp_sweep')
  s = jp_sweep_n_points(sweep, npts)
  write (*, '(a,i0,a)') '# jprom from Fortran, ', npts, ' points'
  write (*, '(a)') '# index omega_rad_s X1_node0_x X1_node1_x'
  do i = 1, npts
    if (jp_sweep_point(sweep, i, omega, amps) /= JPROM_OK) call fail('jp_sweep_point')
    write (*, '(i0,3(1x,es17.10e2))') i - 1, omega, amps(1), amps(2)
    ! the same amplitudes from the full coefficient array: |X1| = sqrt(cos^2 + sin^2)
    if (jp_sweep_point_coeffs(sweep, i, coeffs, msg) /= JPROM_OK) call fail('jp_sweep_point_coeffs')
    if (any(abs(hypot(coeffs(:, 2), coeffs(:, 3)) - amps) > 1.0d-12 * maxval(amps))) then
      msg = 'amplitudes disagree with the coefficients'
      call fail('jp_sweep_point_coeffs')
    end if
  end do
  s = jp_sweep_free(sweep)
  s = jp_model_free(model)

contains
  subroutine fail(what)
    character(len=*), intent(in) :: what
    write (*, '(a,a,a)') what, ' failed: ', trim(msg)
    error stop 1
  end subroutine
end program

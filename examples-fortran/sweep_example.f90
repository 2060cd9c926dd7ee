! jprom from Fortran: the same model, sweep and JP workflow as examples-c/sweep_example.c,
! same output.
program sweep_example
  use, intrinsic :: iso_c_binding
  use jprom
  implicit none
  integer, parameter :: n = 6
  real(c_double) :: mass(n, n), stiffness(n, n), frame(3, 3), fc(n), fs(n), omega, amps(2), coeffs(2, 7)
  type(c_ptr) :: model, sweep, basis
  type(jprom_hbm_options) :: opts
  type(jprom_sweep_options) :: sweep_opts
  type(jprom_jp_options) :: jp_opts
  character(len=512) :: msg
  integer :: d, i, npts, s, sizes(0:7), hh, ncorr, why
  real(c_double) :: e1, judged

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

  ! Jacobian Projection: a predicted basis, then the self-correcting NLR sweep with e*_1 per point
  call jp_default_jp_options(jp_opts)
  if (jp_basis_predict(model, opts, jp_opts, sweep_opts%omega_start, sweep_opts%omega_end, basis, msg) /= JPROM_OK) &
    call fail('jp_basis_predict')
  if (jp_basis_sizes(basis, sizes, hh) /= JPROM_OK) call fail('jp_basis_sizes')
  write (*, '(a,i0,a,*(1x,i0))') '# JP: predicted basis sizes n_h, h = 0..', hh, ':', sizes(0:hh)
  s = jp_basis_free(basis)
  if (jp_rom_sweep_adaptive(model, JPROM_ROM_NLR, opts, sweep_opts, jp_opts, sweep, basis, msg) /= JPROM_OK) &
    call fail('jp_rom_sweep_adaptive')
  s = jp_sweep_n_points(sweep, npts)
  s = jp_sweep_n_corrections(sweep, ncorr)
  s = jp_basis_sizes(basis, sizes, hh)
  write (*, '(a,i0,a,i0,a,i0)') '# JP: self-correcting NLR sweep, ', npts, ' points, ', ncorr, ' corrections, final n_1 = ', &
    sizes(1)
  ! why the corrections ended: above the threshold the basis stayed poor
  if (jp_sweep_correction_end(sweep, why, judged, msg) /= JPROM_OK) call fail('jp_sweep_correction_end')
  write (*, '(a,a,a,g0.3,a,g0.3,a)') '# JP: corrections ended: ', jp_correction_end_name(why), ', judged error ', judged, &
    ' (threshold ', jp_opts%threshold, ')'
  write (*, '(a)') '# index omega_rad_s X1_node0_x X1_node1_x e_star_1'
  do i = 1, npts
    if (jp_sweep_point(sweep, i, omega, amps) /= JPROM_OK) call fail('jp_sweep_point')
    if (jp_sweep_point_error(sweep, i, 1, e1) /= JPROM_OK) call fail('jp_sweep_point_error')
    write (*, '(i0,4(1x,es17.10e2))') i - 1, omega, amps(1), amps(2), e1
  end do
  s = jp_sweep_free(sweep)
  s = jp_basis_free(basis)
  s = jp_model_free(model)

contains
  subroutine fail(what)
    character(len=*), intent(in) :: what
    write (*, '(a,a,a)') what, ' failed: ', trim(msg)
    error stop 1
  end subroutine
end program

! A sweep forced to stall (max_iterations = 1, min_step = max_step) reports why it ended, from Fortran: prints
! "end <reason code>: <text>" for a normal and for the forced sweep and stops with code 1 unless
! the normal one reached the end and the forced one stalled with its reason in words.
program sweep_end
  use, intrinsic :: iso_c_binding
  use jprom_c
  use jprom
  implicit none
  integer, parameter :: n = 6
  real(c_double) :: mass(n, n), stiffness(n, n), frame(3, 3), f1(n), f0(n)
  type(c_ptr) :: model
  integer :: d, normal, forced
  character(len=256) :: message

  mass = 0; stiffness = 0
  do d = 1, 3
    mass(d, d) = 1; mass(3 + d, 3 + d) = 1
    stiffness(d, d) = 2.0d4; stiffness(3 + d, 3 + d) = 1.0d4
    stiffness(d, 3 + d) = -1.0d4; stiffness(3 + d, d) = -1.0d4
  end do
  frame = 0; frame(1, 1) = 1; frame(2, 2) = 1; frame(3, 3) = 1
  f1 = 0; f1(1) = 1; f0 = 0  ! stuck at the band start
  if (jp_model_new(mass, stiffness, model, message) /= JPROM_OK) stop 2
  if (jp_add_ground_contact(model, [4, 5, 6], frame, 3.0d4, 3.0d4, 5.0d4, 0.5d0, 20.0d0, message) /= JPROM_OK) stop 2
  if (jp_set_damping(model, 0.0d0, 1.0d-4, message) /= JPROM_OK) stop 2
  if (jp_set_first_harmonic_force(model, f1, f0, message) /= JPROM_OK) stop 2
  if (jp_set_outputs(model, [1, 4]) /= JPROM_OK) stop 2
  normal = end_of(400)
  forced = end_of(1)
  d = jp_model_free(model)
  if (normal /= JPROM_SWEEP_REACHED_END .or. forced /= JPROM_SWEEP_STALLED) then
    print '(a, i0, a, i0)', 'FAIL normal ', normal, ' forced ', forced
    stop 1
  end if
  print '(a)', 'ok'
contains
  integer function end_of(iterations)
    integer, intent(in) :: iterations
    type(jprom_hbm_options) :: opts
    type(jprom_sweep_options) :: band
    type(c_ptr) :: sweep
    character(len=400) :: why
    integer :: s
    call jp_default_options(opts, band)
    opts%max_iterations = int(iterations, c_size_t)
    if (iterations == 1) then
      band%min_step = 0.05d0; band%initial_step = 0.05d0; band%max_step = 0.05d0
    end if
    band%omega_start = 60; band%omega_end = 160
    end_of = -1
    if (jp_sweep(model, opts, band, sweep, message) /= JPROM_OK) return
    if (jp_sweep_end(sweep, end_of, why) /= JPROM_OK) end_of = -1
    print '(a, i0, a, a)', 'end ', end_of, ': ', trim(why)
    if ((end_of == JPROM_SWEEP_REACHED_END) .neqv. (len_trim(why) == 0)) end_of = -1
    s = jp_sweep_free(sweep)
  end function
end program

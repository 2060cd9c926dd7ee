! jprom from Fortran, starting from an FE model on disk: the same CalculiX job, contacts,
! Craig-Bampton and self-correcting JP sweep as examples-c/fe_example.c, and the same table
! (omega, |X1| at the first OUT node along y, e*_1 per point). See that file for the model and
! the choice of the values below.
!
! usage: fe_example_f90 [DECK.inp]
!   default: crates/jprom/tests/data/calculix/block/block.inp (run from the repository root)
!
! Build (from the repository root, after `cargo build --lib`):
!   gfortran fortran/jprom.f90 examples-fortran/fe_example.f90 \
!       -Ltarget/debug -ljprom -Wl,-rpath,$PWD/target/debug -o fe_example_f90
program fe_example
  use, intrinsic :: iso_c_binding
  use jprom
  implicit none
  ! contact (N/mm, N), fixed-interface modes, band (rad/s), damping, force (N): as in the C example
  real(c_double), parameter :: kt = 2.0d3, kn = 2.0d4, mu = 0.3d0, n0 = 1.0d0
  integer, parameter :: cb_modes = 12
  real(c_double), parameter :: zeta = 0.005d0, band_width = 0.15d0, force = 1.0d0
  real(c_double), parameter :: two_pi = 6.283185307179586d0
  real(c_double) :: free_hz(3), stuck_hz(3), modal_force(3), omega_lo, omega_hi
  integer :: k
  character(len=1024) :: deck, msg
  character(len=512) :: why
  real(c_double) :: frame(3, 3), omega, e1, w0_error
  real(c_double), allocatable :: amps(:)
  integer(c_int64_t) :: tip(1024), out_nodes(64), load(8)
  integer :: i, n_dof, n_red, n_contacts, n_outputs, n_tip, n_out, n_load, n, n_corr, reason
  integer :: kind, sizes(0:7), corrections_end
  real(c_double) :: value, before, after, judged
  type(c_ptr) :: fe, model, sweep, basis
  type(jprom_hbm_options) :: opts
  type(jprom_sweep_options) :: band
  type(jprom_jp_options) :: jp

  deck = 'crates/jprom/tests/data/calculix/block/block.inp'
  if (command_argument_count() >= 1) call get_command_argument(1, deck)

  ! 1. the FE model from ccx's .sti/.mas/.dof and the deck's node sets
  call check(jp_fe_load_calculix(trim(deck), fe, msg), 'jp_fe_load_calculix')
  call check(jp_fe_n_dof(fe, n_dof), 'jp_fe_n_dof')
  call check(jp_fe_node_set(fe, 'TIP', tip, n_tip, msg), 'node set TIP')
  call check(jp_fe_node_set(fe, 'OUT', out_nodes, n_out, msg), 'node set OUT')
  call check(jp_fe_node_set(fe, 'LOAD', load, n_load, msg), 'node set LOAD')

  ! 2. contacts on TIP (frame rows t1 = y, t2 = z, n = x), the load along y, outputs along y
  frame = reshape([0d0, 0d0, 1d0, 1d0, 0d0, 0d0, 0d0, 1d0, 0d0], [3, 3])
  do i = 1, n_tip
    call check(jp_fe_add_contact(fe, tip(i), frame, kt, kt, kn, mu, n0, msg), 'jp_fe_add_contact')
  end do
  call check(jp_fe_add_force(fe, load(1), 1, [0d0, force, 0d0], msg), 'jp_fe_add_force')
  do i = 1, n_out
    call check(jp_fe_add_output(fe, out_nodes(i), 2, msg), 'jp_fe_add_output')
  end do

  ! 3. Craig-Bampton to an ordinary jprom model; the FE model can go
  call check(jp_fe_reduce(fe, cb_modes, model, msg), 'jp_fe_reduce')
  i = jp_fe_free(fe)
  call check(jp_model_sizes(model, n_red, n_contacts, n_outputs, msg), 'jp_model_sizes')
  call check(jp_set_modal_damping_ratios(model, [real(c_double) ::], zeta, msg), 'jp_set_modal_damping_ratios')

  ! natural frequencies, contacts open and stuck; the band goes around the stuck mode the load
  ! drives most (largest modal force) of the lowest three
  call check(jp_model_modes(model, .false., free_hz, message=msg), 'jp_model_modes (free)')
  call check(jp_model_modes(model, .true., stuck_hz, modal_force, message=msg), 'jp_model_modes (stuck)')
  k = maxloc(modal_force, 1)
  omega_lo = (1d0 - band_width) * two_pi * stuck_hz(k)
  omega_hi = (1d0 + band_width) * two_pi * stuck_hz(k)
  allocate (amps(n_outputs))

  ! 4. the self-correcting JP sweep (NLR ROM) over the band
  call jp_default_options(opts, band)
  call jp_default_jp_options(jp)
  band%omega_start = omega_lo
  band%omega_end = omega_hi
  call check(jp_rom_sweep_adaptive(model, JPROM_ROM_NLR, opts, band, jp, sweep, basis, msg), 'jp_rom_sweep_adaptive')
  i = jp_sweep_n_points(sweep, n)
  i = jp_sweep_n_corrections(sweep, n_corr)
  i = jp_sweep_end(sweep, reason, why)
  write (*, '(a, a, a, i0, a, i0, a, i0, a)') '# ', trim(deck), ': ', n_dof, ' DoFs, ', n_tip, &
    ' tip contacts, reduced to ', n_red, ' DoFs'
  write (*, '(a, 3(g0.6, a), 3(g0.6, a), 3(g0.3, a))') '# first modes, contacts open: ', free_hz(1), ' ', free_hz(2), ' ', &
    free_hz(3), ' Hz; stuck: ', stuck_hz(1), ' ', stuck_hz(2), ' ', stuck_hz(3), ' Hz (modal force ', modal_force(1), ' ', &
    modal_force(2), ' ', modal_force(3), ')'
  if (reason == JPROM_SWEEP_REACHED_END) why = 'reached_end'
  write (*, '(a, i0, a, i0, a, a)') '# JP NLR sweep: ', n, ' points, ', n_corr, ' basis corrections, end: ', trim(why)
  ! what each correction did: its kind, the judged error before and after it, the basis sizes n_h
  do i = 1, n_corr
    call check(jp_sweep_correction(sweep, i, kind, value, before, after, sizes(0:opts%harmonics), msg), 'jp_sweep_correction')
    write (*, '(a, i0, a, a, a, g0.3, a, g0.3, a, *(1x, i0))') '# correction ', i, ': ', jp_correction_kind_name(kind), &
      ', worst error ', before, ' -> ', after, ', n_h =', sizes(0:opts%harmonics)
  end do
  ! why the corrections ended: above the threshold the basis stayed poor (the sweep holds the best basis found)
  call check(jp_sweep_correction_end(sweep, corrections_end, judged, msg), 'jp_sweep_correction_end')
  write (*, '(a, a, a, g0.3, a, g0.3, a)') '# corrections ended: ', jp_correction_end_name(corrections_end), &
    ', judged error ', judged, ' (threshold ', jp%threshold, ')'
  ! the static term, which the corrections do not judge (docs/formulation.md, 10.6)
  if (jp_sweep_static_error(sweep, w0_error, msg) == JPROM_OK) &
    write (*, '(a, g0.3)') '# static contact displacement error ', w0_error
  write (*, '(a)') '# omega_rad_s X1_out0_y e*_1'
  do i = 1, n
    call check(jp_sweep_point(sweep, i, omega, amps), 'jp_sweep_point')
    call check(jp_sweep_point_error(sweep, i, 1, e1), 'jp_sweep_point_error')
    write (*, '(3es26.17e3)') omega, amps(1), e1
  end do
  i = jp_sweep_free(sweep)
  i = jp_basis_free(basis)
  i = jp_model_free(model)
  if (reason /= JPROM_SWEEP_REACHED_END) error stop 1
contains
  ! every jp_* function returns a status; on error print jprom's message and stop
  subroutine check(status, what)
    integer, intent(in) :: status
    character(len=*), intent(in) :: what
    if (status /= JPROM_OK) then
      write (*, '(a, a, a)') what, ': ', trim(msg)
      error stop 1
    end if
  end subroutine
end program
